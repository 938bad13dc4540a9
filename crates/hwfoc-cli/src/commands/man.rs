//! `hwfoc man`: manual pages generated from the command line's own definitions (clap_mangen):
//! `hwfoc.1` for the command and `hwfoc-SUBCOMMAND.1` for each subcommand, so they never lag
//! behind `--help`.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use clap::Args;
use hwfoc_io::write::{Staging, WriteError};

use crate::error::CliError;
use crate::output::TextSink;

const AFTER_HELP: &str = "\
Examples:
  hwfoc man | man -l -                      # read the command's page now
  hwfoc man -o ~/.local/share/man/man1      # install every page, then: man hwfoc-decode";

/// Options of `hwfoc man`.
#[derive(Debug, Args)]
#[command(after_help = AFTER_HELP)]
pub struct ManArgs {
    /// Write hwfoc.1 and one page per subcommand (hwfoc-decode.1, ...) into DIR, made if
    /// missing; without it, print hwfoc.1 to standard output.
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    pub output: Option<PathBuf>,
}

/// Runs `hwfoc man` for `command` (the whole command line).
pub fn run(args: &ManArgs, command: clap::Command) -> Result<(), CliError> {
    let pages = pages(command).map_err(|source| write_error("the manual page", source))?;
    match &args.output {
        None => {
            let (_, mut page) = pages.into_iter().next().unwrap_or_default();
            let mut out = TextSink::create(None)?;
            out.write(&mut page)?;
            out.flush()
        }
        Some(dir) => write_pages(dir, pages),
    }
}

/// Every page, the command's first: its file name (`hwfoc-decode.1`) and its roff text.
pub fn pages(command: clap::Command) -> io::Result<Vec<(String, Vec<u8>)>> {
    let mut command = command.disable_help_subcommand(true);
    // Built, subcommands know their display names (`hwfoc-decode`) and inherit `--version`.
    command.build();
    let mut pages = Vec::new();
    add_pages(&command, &mut pages)?;
    Ok(pages)
}

/// Adds the page of `command` and then those of its visible subcommands, depth first.
fn add_pages(command: &clap::Command, pages: &mut Vec<(String, Vec<u8>)>) -> io::Result<()> {
    let man = clap_mangen::Man::new(command.clone());
    let mut text = Vec::new();
    man.render(&mut text)?;
    pages.push((man.get_filename(), text));
    for sub in command.get_subcommands().filter(|s| !s.is_hide_set()) {
        add_pages(sub, pages)?;
    }
    Ok(())
}

/// Writes each page into `dir`, each through a temporary file (a [`Staging`]) renamed into
/// place when complete.
fn write_pages(dir: &Path, pages: Vec<(String, Vec<u8>)>) -> Result<(), CliError> {
    let shown = dir.display().to_string();
    fs::create_dir_all(dir).map_err(|source| WriteError::Create {
        output: shown.clone(),
        source,
    })?;
    for (name, text) in pages {
        let path = dir.join(&name);
        let written = Staging::create(&path).and_then(|(staging, mut file)| {
            file.write_all(&text)?;
            drop(file);
            staging.commit()
        });
        written.map_err(|source| write_error(&path.display().to_string(), source))?;
    }
    Ok(())
}

/// A write error naming `output`.
fn write_error(output: &str, source: io::Error) -> CliError {
    CliError::Write(WriteError::Write {
        output: output.to_string(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use clap::{Arg, Command};

    use super::*;

    fn tool() -> Command {
        Command::new("tool")
            .version("1.2.3")
            .about("Does things.")
            .subcommand(
                Command::new("decode")
                    .about("Decodes.")
                    .arg(Arg::new("format").long("format").help("The format.")),
            )
            .subcommand(Command::new("secret").hide(true))
    }

    /// One page for the command and one per visible subcommand, named as `man` looks them up,
    /// with the options in roff.
    #[test]
    fn a_page_per_visible_command() {
        let pages = pages(tool()).unwrap();
        let names: Vec<&str> = pages.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["tool.1", "tool-decode.1"]);
        let decode = String::from_utf8(pages[1].1.clone()).unwrap();
        assert!(decode.starts_with(".ie \\n(.g .ds Aq"), "{decode}");
        assert!(decode.contains(".TH tool-decode 1"), "{decode}");
        assert!(decode.contains("The format."), "{decode}");
    }

    /// The pages land in the directory, made if missing, with no partial file left over; a
    /// link at the name a partial file once had is not followed.
    #[test]
    fn pages_are_written_into_the_directory() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("man1");
        write_pages(&out, pages(tool()).unwrap()).unwrap();
        #[cfg(unix)]
        {
            let victim = dir.path().join("victim");
            fs::write(&victim, "mine").unwrap();
            std::os::unix::fs::symlink(&victim, out.join("tool.1.partial")).unwrap();
            write_pages(&out, pages(tool()).unwrap()).unwrap();
            assert_eq!(fs::read_to_string(&victim).unwrap(), "mine");
            fs::remove_file(out.join("tool.1.partial")).unwrap();
        }
        let mut names: Vec<String> = fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(names, ["tool-decode.1", "tool.1"]);
    }

    /// A directory that cannot be made is an error naming it.
    #[test]
    fn an_impossible_directory_is_reported() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("file");
        fs::write(&file, "").unwrap();
        let err = write_pages(&file.join("man1"), pages(tool()).unwrap()).unwrap_err();
        assert!(err.to_string().contains("man1"), "{err}");
    }
}
