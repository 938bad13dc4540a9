//! The version text of `hwfoc --version`: the package version, and the git commit and its date
//! when the source is a git checkout. Shared by the build script (`build.rs`, which computes it)
//! and the binary's tests (which check its forms without a build).

/// The version text: `0.1.0 (1a2b3c4d5e6f 2026-11-24)`, or `0.1.0` alone when `git` gives no
/// commit (a crate tarball, a source tree copied without `.git`, no `git` installed).
///
/// `git` runs git with the arguments given, in the package's directory, and returns its output
/// trimmed, or `None` if it could not run or failed.
pub fn version_text(version: &str, git: impl Fn(&[&str]) -> Option<String>) -> String {
    // The build script itself must be a file of the checkout git describes: a tarball
    // unpacked inside some other repository must not take that repository's commit.
    if git(&["ls-files", "--error-unmatch", "build.rs"]).is_none() {
        return version.to_string();
    }
    let commit = git(&["rev-parse", "--short=12", "HEAD"]).filter(|c| is_commit(c));
    let date = git(&["log", "-1", "--format=%cs", "HEAD"]).filter(|d| is_date(d));
    match (commit, date) {
        (Some(commit), Some(date)) => format!("{version} ({commit} {date})"),
        (Some(commit), None) => format!("{version} ({commit})"),
        _ => version.to_string(),
    }
}

/// Whether `s` is an abbreviated commit hash: 7 or more hexadecimal digits.
fn is_commit(s: &str) -> bool {
    s.len() >= 7 && s.bytes().all(|b| b.is_ascii_hexdigit())
}

/// Whether `s` is a date as `%cs` gives it: `YYYY-MM-DD`.
fn is_date(s: &str) -> bool {
    let b = s.as_bytes();
    b.len() == 10
        && b.iter().enumerate().all(|(i, c)| {
            if i == 4 || i == 7 {
                *c == b'-'
            } else {
                c.is_ascii_digit()
            }
        })
}

#[cfg(test)]
mod tests {
    use super::version_text;

    /// A fake git: the answer to each command, or `None` for a command it does not know.
    fn git<'a>(answers: &'a [(&'a str, &'a str)]) -> impl Fn(&[&str]) -> Option<String> + 'a {
        move |args| {
            let command = args.join(" ");
            answers
                .iter()
                .find(|(c, _)| *c == command)
                .map(|(_, out)| out.to_string())
        }
    }

    const TRACKED: (&str, &str) = ("ls-files --error-unmatch build.rs", "build.rs");
    const COMMIT: (&str, &str) = ("rev-parse --short=12 HEAD", "84804ab1c2d3");
    const DATE: (&str, &str) = ("log -1 --format=%cs HEAD", "2026-11-24");

    #[test]
    fn a_checkout_gives_the_commit_and_its_date() {
        let text = version_text("0.1.0", git(&[TRACKED, COMMIT, DATE]));
        assert_eq!(text, "0.1.0 (84804ab1c2d3 2026-11-24)");
    }

    #[test]
    fn without_git_or_outside_a_checkout_the_version_alone() {
        // No git at all, as in a crate tarball on a machine without it.
        assert_eq!(version_text("0.1.0", |_| None), "0.1.0");
        // A tarball unpacked inside another repository: build.rs is not one of its files.
        assert_eq!(version_text("0.1.0", git(&[COMMIT, DATE])), "0.1.0");
    }

    #[test]
    fn odd_answers_are_not_taken_for_a_commit_or_a_date() {
        let short = ("rev-parse --short=12 HEAD", "84804a");
        let word = ("rev-parse --short=12 HEAD", "HEAD-not-a-hash");
        let bad_date = ("log -1 --format=%cs HEAD", "24.11.2026");
        assert_eq!(version_text("0.1.0", git(&[TRACKED, short, DATE])), "0.1.0");
        assert_eq!(version_text("0.1.0", git(&[TRACKED, word, DATE])), "0.1.0");
        assert_eq!(
            version_text("0.1.0", git(&[TRACKED, COMMIT, bad_date])),
            "0.1.0 (84804ab1c2d3)"
        );
    }
}
