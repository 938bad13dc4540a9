//! The device-information frame (`9B 4C 01 01`, 77 bytes) an idle ESC sends after each data frame.
//!
//! ```text
//!  0    1    2    3    4 ..= 75                                   76
//!  9B   4C   01   01   72 ASCII bytes, space-padded fixed fields    check = low byte of sum(0..=75)
//! ```
//!
//! The 72 text bytes seen on an XRotor v4 Pro HV 80A are five fixed-width fields:
//! 16 blanks, `XR_FOC_ESC` (16), `HW577_KZ1_V1.1` (16), `XR-01.0.00` (16), `01040443` (8).
//! The vendor document does not describe this frame; only one distinct frame has been seen, so
//! the check byte rule is likely rather than certain, and the text is also exposed whole.
//!
//! The check byte is only 8 bits: a frame cut short and followed by other frames passes it by
//! chance once in 256 times, and would swallow the data frames behind it. So a candidate is also
//! required to carry ASCII text (every byte below 0x80): a data frame inside the 77-byte window
//! always brings its `0x9B` sync byte into the text and is never hidden.
//!
//! The check byte is [`Checksum::Sum8`]: the low byte of the 16-bit sum of bytes 0..=75.

use core::fmt;

use super::{FrameKind, sealed};
use crate::foc::FrameError;
use crate::foc::stats::Stats;
use crate::wire::{Checksum, VERSION};

/// Length byte of a device-information frame: bytes before the check byte.
pub const INFO_LENGTH_BYTE: u8 = 0x4C;
/// Command byte of a device-information frame.
pub const CMD_INFO: u8 = 0x01;
/// Total length of a device-information frame on the wire.
pub const INFO_FRAME_LEN: usize = 77;
/// Number of text bytes carried by a device-information frame.
pub const INFO_TEXT_LEN: usize = 72;

/// Widths of the fixed fields of the text, in order: blank, product, hardware, firmware, id.
const FIELDS: [(usize, usize); 5] = [(0, 16), (16, 32), (32, 48), (48, 64), (64, 72)];
/// Names of the four visible fields, as used in [`InfoFieldError`].
const FIELD_NAMES: [&str; 4] = ["product", "hardware", "firmware", "id"];

/// Why [`InfoFrame::new`] refused a field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum InfoFieldError {
    /// The text does not fit its fixed-width field.
    TooLong {
        /// Which field: `product`, `hardware`, `firmware` or `id`.
        field: &'static str,
        /// Bytes the field holds.
        max: usize,
        /// Bytes given.
        len: usize,
    },
    /// The text is not ASCII.
    NotAscii {
        /// Which field.
        field: &'static str,
    },
}

impl fmt::Display for InfoFieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            InfoFieldError::TooLong { field, max, len } => {
                write!(f, "{field} is {len} bytes long; the field holds {max}")
            }
            InfoFieldError::NotAscii { field } => write!(f, "{field} is not ASCII text"),
        }
    }
}

impl core::error::Error for InfoFieldError {}

/// A device-information frame: 72 bytes of space-padded ASCII text.
///
/// ```
/// use hwfoc::foc::InfoFrame;
///
/// let info = InfoFrame::new("XR_FOC_ESC", "HW577_KZ1_V1.1", "XR-01.0.00", "01040443")?;
/// let bytes = info.encode();
/// assert_eq!(&bytes[..4], &[0x9B, 0x4C, 0x01, 0x01]);
/// assert_eq!(bytes[76], 0x34); // the check byte of the real frame
/// let back = InfoFrame::parse(&bytes)?;
/// assert_eq!(back.product(), "XR_FOC_ESC");
/// assert_eq!(back.firmware(), "XR-01.0.00");
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct InfoFrame {
    text: [u8; INFO_TEXT_LEN],
}

impl InfoFrame {
    /// Builds a frame from its four visible fields (the leading 16-byte field is left blank).
    ///
    /// The first three fields take at most 16 ASCII bytes, `id` at most 8; each is padded with
    /// spaces.
    pub fn new(
        product: &str,
        hardware: &str,
        firmware: &str,
        id: &str,
    ) -> Result<Self, InfoFieldError> {
        let mut text = [b' '; INFO_TEXT_LEN];
        let fields = [product, hardware, firmware, id];
        for ((value, &(start, end)), &field) in fields.iter().zip(&FIELDS[1..]).zip(&FIELD_NAMES) {
            let max = end - start;
            if !value.is_ascii() {
                return Err(InfoFieldError::NotAscii { field });
            }
            if value.len() > max {
                return Err(InfoFieldError::TooLong {
                    field,
                    max,
                    len: value.len(),
                });
            }
            text[start..start + value.len()].copy_from_slice(value.as_bytes());
        }
        Ok(InfoFrame { text })
    }

    /// Builds a frame carrying exactly these 72 text bytes, which must be ASCII (as every
    /// frame the decoder accepts is).
    pub fn from_text(text: [u8; INFO_TEXT_LEN]) -> Result<Self, InfoFieldError> {
        if !text.is_ascii() {
            return Err(InfoFieldError::NotAscii { field: "text" });
        }
        Ok(InfoFrame { text })
    }

    /// Decodes a device-information frame from the first 77 bytes of `bytes`.
    pub fn parse(bytes: &[u8]) -> Result<Self, FrameError> {
        <Self as FrameKind>::parse(bytes)
    }

    /// Encodes the frame as the 77 bytes an ESC sends.
    pub fn encode(&self) -> [u8; INFO_FRAME_LEN] {
        let mut f = [0u8; INFO_FRAME_LEN];
        self.encode_into(&mut f);
        f
    }

    /// The 72 text bytes exactly as received.
    pub fn text(&self) -> &[u8; INFO_TEXT_LEN] {
        &self.text
    }

    /// The fixed-width field `index` (0..5) with its padding removed.
    fn field(&self, index: usize) -> &str {
        let (start, end) = FIELDS[index];
        ascii(&self.text[start..end]).trim_matches(|c: char| c == ' ' || c == '\0')
    }

    /// Product name (text bytes 16..32), e.g. `XR_FOC_ESC`.
    pub fn product(&self) -> &str {
        self.field(1)
    }

    /// Hardware version (text bytes 32..48), e.g. `HW577_KZ1_V1.1`.
    pub fn hardware(&self) -> &str {
        self.field(2)
    }

    /// Firmware version (text bytes 48..64), e.g. `XR-01.0.00`.
    pub fn firmware(&self) -> &str {
        self.field(3)
    }

    /// The trailing 8-character identifier (text bytes 64..72), e.g. `01040443`. Its meaning
    /// (serial or build number) is not documented by the vendor.
    pub fn id(&self) -> &str {
        self.field(4)
    }

    /// The whitespace-separated words of the text, in order: robust to a layout other than the
    /// one seen so far.
    pub fn words(&self) -> impl Iterator<Item = &str> + '_ {
        self.text
            .split(|&b| b == b' ' || b == 0)
            .filter(|w| !w.is_empty())
            .map(ascii)
    }
}

impl FrameKind for InfoFrame {
    const LENGTH_BYTE: u8 = INFO_LENGTH_BYTE;
    const VERSION: u8 = VERSION;
    const COMMAND: u8 = CMD_INFO;
    const LEN: usize = INFO_FRAME_LEN;
    const CHECKSUM: Checksum = Checksum::Sum8;
}

impl sealed::Sealed for InfoFrame {
    #[inline]
    fn read(frame: &[u8]) -> Result<Self, FrameError> {
        let Some(f) = frame.first_chunk::<INFO_FRAME_LEN>() else {
            return Err(FrameError::Truncated {
                needed: INFO_FRAME_LEN,
                got: frame.len(),
            });
        };
        if let Some((at, found)) = first_non_ascii(&f[4..76]) {
            return Err(FrameError::NotText {
                offset: 4 + at,
                found,
            });
        }
        let mut text = [0u8; INFO_TEXT_LEN];
        text.copy_from_slice(&f[4..76]);
        Ok(InfoFrame { text })
    }

    fn write(&self, payload: &mut [u8]) {
        payload.copy_from_slice(&self.text);
    }

    #[inline(always)]
    fn count(&self, stats: &mut Stats) {
        stats.info_frame();
    }
}

/// Offset and value of the first byte of `text` that is not ASCII, looked for a machine word at
/// a time (4 bytes on a Cortex-M, 8 on a PC: 18 or 9 steps for the 72 text bytes, one loop).
#[inline]
fn first_non_ascii(text: &[u8]) -> Option<(usize, u8)> {
    const WORD: usize = size_of::<usize>();
    const HIGH: usize = usize::from_ne_bytes([0x80; WORD]);
    let mut words = text.chunks_exact(WORD);
    for (i, w) in words.by_ref().enumerate() {
        let word = usize::from_le_bytes(w.try_into().unwrap_or([0; WORD]));
        if word & HIGH != 0 {
            let bit = (word & HIGH).trailing_zeros() & !7;
            return Some((i * WORD + bit as usize / 8, (word >> bit) as u8));
        }
    }
    let rest = words.remainder();
    let at = rest.iter().position(|b| !b.is_ascii())?;
    Some((text.len() - rest.len() + at, rest[at]))
}

/// ASCII bytes as text (an `InfoFrame` holds nothing else; `"?"` would mark a broken invariant).
fn ascii(bytes: &[u8]) -> &str {
    core::str::from_utf8(bytes).unwrap_or("?")
}

impl fmt::Debug for InfoFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("InfoFrame")
            .field("product", &self.product())
            .field("hardware", &self.hardware())
            .field("firmware", &self.firmware())
            .field("id", &self.id())
            .finish()
    }
}

impl fmt::Display for InfoFrame {
    /// The words of the text joined by single spaces.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, w) in self.words().enumerate() {
            if i > 0 {
                f.write_str(" ")?;
            }
            f.write_str(w)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_non_ascii_matches_a_plain_search() {
        let plain = |t: &[u8]| t.iter().position(|b| !b.is_ascii()).map(|at| (at, t[at]));
        let mut text = [b' '; INFO_TEXT_LEN];
        assert_eq!(first_non_ascii(&text), None);
        for at in 0..INFO_TEXT_LEN {
            for bad in [0x80, 0x9B, 0xFF] {
                text[at] = bad;
                assert_eq!(first_non_ascii(&text), Some((at, bad)));
                if at + 3 < INFO_TEXT_LEN {
                    text[at + 3] = 0xC0; // a later one changes nothing
                    assert_eq!(first_non_ascii(&text), Some((at, bad)));
                    text[at + 3] = b'x';
                }
                text[at] = 0x7F;
                assert_eq!(first_non_ascii(&text), plain(&text));
            }
        }
        // Lengths that leave a remainder after whole words.
        for len in 0..20 {
            let mut t = [b'a'; 20];
            if len > 0 {
                t[len - 1] = 0xA5;
            }
            assert_eq!(first_non_ascii(&t[..len]), plain(&t[..len]), "{len}");
        }
    }
}
