//! What the bytes of a raw input look like, when they held no telemetry frame: a text file, a
//! file of zeros, a file of a known format. Said instead of the advice about the baud rate and
//! the wiring, which fits a capture of a wire, not a README given by mistake.

use std::fmt;

/// How many of an input's first bytes are looked at.
pub(crate) const SAMPLE: usize = 4096;

/// What a raw input that held no frame looks like.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Looks {
    /// Printable text (UTF-8): a document, a CSV or JSON file, a configuration.
    Text,
    /// Nothing but zero bytes.
    Zeros,
    /// A file format known by its first bytes, named.
    Format(&'static str),
    /// A CAN log's frames, in which no ESC status was found (see [`crate::Input::looks`]): how
    /// many, how many of them with 11-bit ids (DroneCAN's are 29-bit), and how many nodes sent
    /// 29-bit frames (their id's low 7 bits).
    Can {
        /// Classic CAN frames in the log.
        frames: u64,
        /// Those with an 11-bit (standard) id.
        standard: u64,
        /// Source nodes of the 29-bit frames.
        nodes: u32,
    },
    /// Binary bytes, as a wire gives, in which no frame of any format was found: how many were
    /// looked at, and how many of them are lead bytes of a Hobbywing format (`9B`: HW-FOC,
    /// DataLink, V4, V3; `FE`: HW5).
    Unframed {
        /// Bytes looked at (the input's first, up to 4096).
        bytes: usize,
        /// `9B` bytes among them.
        sync_9b: usize,
        /// `FE` bytes among them.
        sync_fe: usize,
    },
}

/// Known formats by their first bytes: those a user is likely to give by mistake.
const MAGIC: &[(&[u8], &str)] = &[
    (b"\x89PNG\r\n\x1a\n", "a PNG image"),
    (b"\xff\xd8\xff", "a JPEG image"),
    (b"GIF8", "a GIF image"),
    (b"%PDF", "a PDF document"),
    (b"PK\x03\x04", "a ZIP archive (or an Office document)"),
    (b"\x1f\x8b", "a gzip file"),
    (b"BZh", "a bzip2 file"),
    (b"\xfd7zXZ\x00", "an xz file"),
    (b"\x28\xb5\x2f\xfd", "a zstd file"),
    (b"\x7fELF", "an executable (ELF)"),
    (b"PAR1", "a Parquet file"),
    (b"SQLite format 3\x00", "an SQLite database"),
    (b"ARROW1", "an Arrow file"),
];

impl Looks {
    /// What `head`, an input's first bytes (up to its first 4096), looks like when it held no
    /// frame: something other than telemetry, or [`Looks::Unframed`] binary bytes (a capture at
    /// the wrong baud rate, say); `None` for no bytes.
    pub fn of(head: &[u8]) -> Option<Looks> {
        Self::other_than_telemetry(head).or_else(|| {
            (!head.is_empty()).then(|| Looks::Unframed {
                bytes: head.len(),
                sync_9b: head.iter().filter(|&&b| b == hwfoc::wire::SYNC).count(),
                sync_fe: head.iter().filter(|&&b| b == hwfoc::hw5::ESC_START).count(),
            })
        })
    }

    /// Whether `head` is something other than telemetry: text, zeros, a known file format.
    pub fn is_other_than_telemetry(&self) -> bool {
        !matches!(self, Looks::Unframed { .. } | Looks::Can { .. })
    }

    /// What `head` looks like, if it is something other than telemetry.
    fn other_than_telemetry(head: &[u8]) -> Option<Looks> {
        if head.is_empty() {
            return None;
        }
        if let Some(&(_, name)) = MAGIC.iter().find(|(magic, _)| head.starts_with(magic)) {
            return Some(Looks::Format(name));
        }
        if head.iter().all(|&b| b == 0) {
            return Some(Looks::Zeros);
        }
        // UTF-8, allowing a character cut at the end of the sample; printable but for tabs
        // and line ends. HW-FOC frames start with 0x9B, never a byte of text.
        let text = match std::str::from_utf8(head) {
            Ok(t) => t,
            Err(e) if e.error_len().is_none() => {
                std::str::from_utf8(&head[..e.valid_up_to()]).unwrap_or_default()
            }
            Err(_) => return None,
        };
        let printable = text
            .chars()
            .filter(|c| !c.is_control() || matches!(c, '\t' | '\n' | '\r'))
            .count();
        let all = text.chars().count();
        // Text has words: white space and more than a few different characters (a byte
        // repeated, 0x55 "UUUU", is a line's pattern, not a document).
        let mut distinct: Vec<char> = text.chars().take(512).collect();
        distinct.sort_unstable();
        distinct.dedup();
        let words = text.chars().any(char::is_whitespace) && distinct.len() >= 4;
        (all > 0 && words && printable * 100 >= all * 98).then_some(Looks::Text)
    }
}

impl fmt::Display for Looks {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Looks::Text => f.write_str("text, not telemetry"),
            Looks::Zeros => f.write_str("only zero bytes, not telemetry"),
            Looks::Format(name) => write!(f, "looks like {name}, not telemetry"),
            Looks::Can { frames: 0, .. } => f.write_str("no CAN frame in the log"),
            Looks::Can {
                frames,
                standard,
                nodes,
            } => write!(
                f,
                "{frames} CAN frames ({standard} with 11-bit ids, which DroneCAN does not use; \
                 29-bit frames from {nodes} nodes) and no ESC status of DroneCAN from any node: \
                 a log of another bus, or of ESCs not set to DroneCAN"
            ),
            Looks::Unframed {
                bytes,
                sync_9b,
                sync_fe,
            } => write!(
                f,
                "no valid frame of any Hobbywing format in {bytes} bytes ({sync_9b} 9B and \
                 {sync_fe} FE lead bytes among the first): check the baud rate (19200; 115200 \
                 for DataLink and HW5) and the wiring"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Looks;

    #[test]
    fn text_zeros_and_formats_are_told_from_telemetry() {
        assert_eq!(
            Looks::of(b"# hwfoc\n\nThe open toolkit\n"),
            Some(Looks::Text)
        );
        assert_eq!(
            Looks::of("t_s,esc\n1.5,0\nnaïve °C".as_bytes()),
            Some(Looks::Text)
        );
        // A character cut at the end of the sample is still text.
        let cut = "mos temperature 25 °C".as_bytes();
        assert_eq!(Looks::of(&cut[..cut.len() - 2]), Some(Looks::Text));
        assert_eq!(Looks::of(&[0; 300]), Some(Looks::Zeros));
        assert_eq!(
            Looks::of(b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR"),
            Some(Looks::Format("a PNG image"))
        );
        assert_eq!(
            Looks::of(b"PAR1\x15\x04"),
            Some(Looks::Format("a Parquet file"))
        );
        assert_eq!(Looks::of(b""), None);
    }

    #[test]
    fn telemetry_and_noise_look_like_nothing_else() {
        // HW-FOC frames (0x9B lead byte), a capture at the wrong baud rate, random bytes: binary
        // bytes, described by their lead bytes.
        let frames: Vec<u8> = (0..10)
            .flat_map(|_| hwfoc::foc::DataFrame::default().encode())
            .collect();
        let unframed = |bytes, sync_9b, sync_fe| {
            Some(Looks::Unframed {
                bytes,
                sync_9b,
                sync_fe,
            })
        };
        assert_eq!(Looks::of(&frames), unframed(240, 10, 0));
        let mut x: u32 = 12345;
        let noise: Vec<u8> = (0..4096)
            .map(|_| {
                x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
                (x >> 16) as u8
            })
            .collect();
        let looks = Looks::of(&noise).unwrap();
        assert!(!looks.is_other_than_telemetry(), "{looks:?}");
        assert!(
            looks
                .to_string()
                .starts_with("no valid frame of any Hobbywing format in 4096 bytes (")
        );
        // One byte repeated is a line's pattern, not text.
        assert_eq!(Looks::of(&[0x55; 4096]), unframed(4096, 0, 0));
        // Text with a few control bytes in it is not text.
        assert_eq!(Looks::of(b"abc\x01\x02\x03\x04def"), unframed(10, 0, 0));
        assert_eq!(
            Looks::of(&[0xFE, 0x9B, 0x9B]).unwrap().to_string(),
            "no valid frame of any Hobbywing format in 3 bytes (2 9B and 1 FE lead bytes among \
             the first): check the baud rate (19200; 115200 for DataLink and HW5) and the wiring"
        );
    }

    #[test]
    fn it_reads_as_a_reason() {
        assert_eq!(Looks::Text.to_string(), "text, not telemetry");
        assert_eq!(
            Looks::Format("a PNG image").to_string(),
            "looks like a PNG image, not telemetry"
        );
    }
}
