//! A recording's identity: which files are parts of one recording.

use std::fmt;

/// The identity of one recording: a random UUID that `hwfoc record` (and `monitor --record`,
/// `simulate`) writes into the section header of every file it writes in one run, rotated files
/// alike, as the comment `hwfoc recording UUID`.
///
/// Port names (`/dev/ttyUSB0`, `esc-0`) are the same on every drone and laptop, so they cannot
/// tell whether two files hold one ESC: files that carry the same id are parts of one
/// recording (their ports go on from file to file), files with different ids (or none) are not,
/// unless the user says so (`--join`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct RecordingId(uuid::Uuid);

/// What the section header's comment starts with.
const PREFIX: &str = "hwfoc recording ";

impl RecordingId {
    /// A new, random identity (UUID version 4).
    pub fn new() -> RecordingId {
        RecordingId(uuid::Uuid::new_v4())
    }

    /// The id a section header comment names, if it is one (`hwfoc recording UUID`).
    pub fn from_comment(comment: &str) -> Option<RecordingId> {
        let rest = comment.strip_prefix(PREFIX)?;
        uuid::Uuid::try_parse(rest.trim()).ok().map(RecordingId)
    }

    /// The section header comment that names it.
    pub fn comment(&self) -> String {
        format!("{PREFIX}{}", self.0.hyphenated())
    }
}

impl Default for RecordingId {
    fn default() -> Self {
        RecordingId::new()
    }
}

impl fmt::Display for RecordingId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0.hyphenated())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_id_is_read_back_from_its_comment_and_ids_differ() {
        let a = RecordingId::new();
        assert_eq!(RecordingId::from_comment(&a.comment()), Some(a));
        assert_ne!(RecordingId::new(), a);
        assert_eq!(RecordingId::from_comment("a note"), None);
        assert_eq!(
            RecordingId::from_comment("hwfoc recording not-a-uuid"),
            None
        );
    }
}
