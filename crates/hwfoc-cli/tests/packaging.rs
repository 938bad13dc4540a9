//! The command as an installed tool: shell completions loaded by real shells, manual pages that
//! render, and `--version` naming the commit it was built from.

mod common;

#[path = "../build_info.rs"]
mod build_info;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{Dir, hwfoc, need, ok, stdout};

/// Whether `program` runs here (`program --version` succeeds).
fn installed(program: &str) -> bool {
    Command::new(program)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Runs `script` with `shell -c`, `hwfoc` being the binary under test (a function or alias of
/// the shell is not needed: the script calls it by its path in `$HWFOC`).
fn shell(shell: &str, script: &str) -> Output {
    Command::new(shell)
        .args(["-c", script])
        .env("HWFOC", env!("CARGO_BIN_EXE_hwfoc"))
        .output()
        .unwrap_or_else(|e| panic!("{shell}: {e}"))
}

/// The subcommands `hwfoc --help` lists (the `Commands:` section), `help` left out.
fn subcommands() -> Vec<String> {
    let help = stdout(&hwfoc().arg("--help").output().unwrap());
    let section = help.split("Commands:").nth(1).expect("a Commands: section");
    let names: Vec<String> = section
        .lines()
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        // A name starts a line after two spaces; a wrapped description is indented further.
        .filter(|l| !l.starts_with("   "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|&n| n != "help" && n.chars().all(|c| c.is_ascii_lowercase() || c == '-'))
        .map(str::to_string)
        .collect();
    assert!(names.len() >= 8, "{names:?}");
    names
}

#[test]
fn bash_loads_the_completion_and_completes_subcommands_and_options() {
    let out = shell(
        "bash",
        r#"source <("$HWFOC" completions bash) || exit 1
complete -p hwfoc || exit 1
COMP_WORDS=(hwfoc de); COMP_CWORD=1; _hwfoc hwfoc de hwfoc
echo "subcommands: ${COMPREPLY[*]}"
COMP_WORDS=(hwfoc decode --for); COMP_CWORD=2; _hwfoc hwfoc --for decode
echo "options: ${COMPREPLY[*]}"
COMP_WORDS=(hwfoc decode --format ''); COMP_CWORD=3; _hwfoc hwfoc '' --format
echo "values: ${COMPREPLY[*]}""#,
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("-F _hwfoc hwfoc"), "{text}");
    assert!(text.contains("subcommands: decode"), "{text}");
    assert!(text.contains("options: --format"), "{text}");
    assert!(text.contains("values: jsonl csv parquet"), "{text}");
}

#[test]
#[ignore = "needs zsh: .ci/run installs it and runs this with --ignored"]
fn zsh_loads_the_completion() {
    assert!(
        installed("zsh"),
        "needs zsh: install it (Debian: apt-get install zsh), as .ci/run does"
    );
    let out = shell(
        "zsh",
        r#"autoload -U compinit && compinit -u -D
source <("$HWFOC" completions zsh) || exit 1
print -r -- "registered: $_comps[hwfoc]"
whence -w _hwfoc"#,
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("registered: _hwfoc"), "{text}");
    assert!(text.contains("_hwfoc: function"), "{text}");
}

#[test]
#[ignore = "needs fish: .ci/run installs it and runs this with --ignored"]
fn fish_loads_the_completion_and_completes_subcommands() {
    assert!(
        installed("fish"),
        "needs fish: install it (Debian: apt-get install fish), as .ci/run does"
    );
    let out = shell(
        "fish",
        r#""$HWFOC" completions fish | source; or exit 1
complete --do-complete 'hwfoc de'
complete --do-complete 'hwfoc decode --form'"#,
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.lines().any(|l| l.starts_with("decode")), "{text}");
    assert!(text.lines().any(|l| l.starts_with("--format")), "{text}");
}

#[test]
fn every_shell_gets_a_script_and_an_unknown_one_is_refused() {
    for (sh, marker) in [
        ("bash", "-F _hwfoc"),
        ("zsh", "#compdef hwfoc"),
        ("fish", "complete -c hwfoc"),
        ("powershell", "Register-ArgumentCompleter"),
        ("elvish", "edit:completion:arg-completer[hwfoc]"),
    ] {
        let text = stdout(&hwfoc().args(["completions", sh]).output().unwrap());
        assert!(text.contains(marker), "{sh}: {marker:?} not in the script");
        assert!(text.contains("simulate"), "{sh}");
    }
    let out = hwfoc().args(["completions", "tcsh"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("tcsh"));
}

/// The page rendered by groff as `man` does (`-k`: UTF-8 input through preconv): no warning,
/// and the text.
fn render(page: &Path) -> String {
    let out = Command::new("groff")
        .args(["-k", "-man", "-Tutf8", "-ww", "-z"])
        .arg(page)
        .output()
        .unwrap();
    assert!(
        out.status.success() && out.stderr.is_empty(),
        "{}: {}",
        page.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let out = Command::new("groff")
        .args(["-k", "-man", "-Tutf8", "-P-cbou"])
        .arg(page)
        .output()
        .unwrap();
    String::from_utf8(out.stdout).unwrap()
}

/// `hwfoc man -o DIR` in a fresh directory: the directory, and the pages written (sorted), checked
/// to be one for the command and each subcommand, the same as `hwfoc man` prints for the command.
fn write_man_pages() -> (Dir, PathBuf, Vec<String>) {
    let dir = Dir::new();
    let out_dir = dir.path("share/man/man1");
    ok(hwfoc()
        .args(["man", "-o", out_dir.to_str().unwrap()])
        .output()
        .unwrap());
    let mut pages = vec!["hwfoc.1".to_string()];
    pages.extend(subcommands().iter().map(|s| format!("hwfoc-{s}.1")));
    // A subcommand's own subcommands have pages too.
    pages.extend(["install", "path", "print"].map(|s| format!("hwfoc-wireshark-{s}.1")));
    pages.extend(["list", "set-id", "set", "self-test"].map(|s| format!("hwfoc-can-{s}.1")));
    let mut written: Vec<String> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    written.sort();
    pages.sort();
    assert_eq!(written, pages);
    // Without -o: the command's page on standard output, the same as the file.
    let main_page = stdout(&hwfoc().arg("man").output().unwrap());
    assert_eq!(
        main_page,
        std::fs::read_to_string(out_dir.join("hwfoc.1")).unwrap()
    );
    // At least roff: a title line, and the sections.
    for page in &pages {
        let text = std::fs::read_to_string(out_dir.join(page)).unwrap();
        assert!(text.contains(".TH ") && text.contains(".SH NAME"), "{page}");
    }
    (dir, out_dir, pages)
}

#[test]
fn man_pages_for_the_command_and_every_subcommand_are_written() {
    write_man_pages();
}

#[test]
#[ignore = "needs groff: .ci/run installs it and runs this with --ignored"]
fn man_pages_for_the_command_and_every_subcommand_render() {
    need(installed("groff"), "groff");
    let (_dir, out_dir, pages) = write_man_pages();
    for page in &pages {
        let text = render(&out_dir.join(page));
        let name = page.trim_end_matches(".1");
        for section in ["NAME", "SYNOPSIS", "DESCRIPTION", "OPTIONS", "VERSION"] {
            assert!(text.contains(section), "{page}: no {section}:\n{text}");
        }
        assert!(text.contains(name), "{page}:\n{text}");
        assert!(text.contains("--help"), "{page}:\n{text}");
    }
    let decode = render(&out_dir.join("hwfoc-decode.1"));
    assert!(decode.contains("--format"), "{decode}");
    assert!(decode.contains("parquet"), "{decode}");
    let main_page = render(&out_dir.join("hwfoc.1"));
    assert!(main_page.contains("hwfoc-decode(1)"), "{main_page}");
}

#[test]
fn man_reports_a_directory_it_cannot_make() {
    let dir = Dir::new();
    std::fs::write(dir.path("file"), "").unwrap();
    let target = dir.arg("file/man1");
    let out = hwfoc().args(["man", "-o", &target]).output().unwrap();
    common::assert_fails_with(&out, &target);
}

/// Git's answer in the package's directory, if it is a git checkout with git installed.
fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8(out.stdout).unwrap().trim().to_string())
}

#[test]
fn version_names_the_commit_and_its_date_in_a_checkout() {
    let version = stdout(&hwfoc().arg("--version").output().unwrap());
    let version = version.trim_end();
    let plain = format!("hwfoc {}", env!("CARGO_PKG_VERSION"));
    let head = git(&["rev-parse", "HEAD"]);
    let tracked = git(&["ls-files", "--error-unmatch", "build.rs"]).is_some();
    let (Some(head), true) = (head, tracked) else {
        // A source tree outside git: the version alone.
        assert_eq!(version, plain);
        return;
    };
    let date = git(&["log", "-1", "--format=%cs", "HEAD"]).unwrap();
    let rest = version
        .strip_prefix(&format!("{plain} ("))
        .and_then(|r| r.strip_suffix(')'))
        .unwrap_or_else(|| panic!("{version:?}"));
    let (commit, commit_date) = rest.split_once(' ').unwrap();
    assert!(
        commit.len() >= 7 && commit.bytes().all(|b| b.is_ascii_hexdigit()),
        "{version}"
    );
    assert!(head.starts_with(commit), "{version}: HEAD is {head}");
    assert_eq!(commit_date, date, "{version}");
    // Subcommands say the same.
    let sub = stdout(&hwfoc().args(["decode", "--version"]).output().unwrap());
    assert_eq!(sub.trim_end(), version.replacen("hwfoc", "hwfoc-decode", 1));
}
