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

    /// An id made from `parts` alone (the same parts, the same id), for a writer whose bytes
    /// must be the same run after run: the simulator's, from its seed and start time. Ids of
    /// different parts differ as random ones do (the parts are mixed by SplitMix64, then laid
    /// out as a version 4 UUID).
    pub fn derived(parts: &[u64]) -> RecordingId {
        let mut state = 0x6877_666f_6320_7265u64; // "hwfoc re"
        let mut next = |x: u64| {
            // SplitMix64 (Steele, Lea and Flood): a well-mixed 64-bit output per input.
            state = state.wrapping_add(x).wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        for &p in parts {
            next(p);
        }
        let (hi, lo) = (next(1), next(2));
        let mut bytes = [0u8; 16];
        bytes[..8].copy_from_slice(&hi.to_le_bytes());
        bytes[8..].copy_from_slice(&lo.to_le_bytes());
        RecordingId(uuid::Builder::from_random_bytes(bytes).into_uuid())
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
        let d = RecordingId::derived(&[7, 1_000_000_000]);
        assert_eq!(d, RecordingId::derived(&[7, 1_000_000_000]));
        assert_ne!(d, RecordingId::derived(&[8, 1_000_000_000]));
        assert_ne!(d, RecordingId::derived(&[7, 2_000_000_000]));
        assert_eq!(RecordingId::from_comment(&d.comment()), Some(d));
    }
}
