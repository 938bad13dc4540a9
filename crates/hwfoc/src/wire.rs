//! What the Hobbywing protocols share on the wire: byte timing ([`byte_ns`]), the sync and
//! version bytes, and the kinds of check bytes ([`Checksum`]: the sums of HW-FOC
//! ([`crate::foc`]), the CRC-16/XMODEM of DataLink V2 ([`crate::datalink`]), the CRC-16/MODBUS
//! of HW5 ([`crate::hw5`])).
//!
//! This is the lowest layer of the codec: it knows no particular protocol or frame kind. Each
//! protocol's frames are built on top of it in its own module.
//!
//! Every HW-FOC frame (and a DataLink V2 frame) has the same outline:
//!
//! ```text
//!  0      1             2        3        4 ..              LEN - w .. LEN
//!  9B     length byte   version  command  payload           check bytes (w = 1 or 2)
//! ```
//!
//! The length byte counts the bytes before the check bytes (`LEN - w`) and is what tells the
//! kinds apart; version and command are then checked against the kind (see
//! `docs/PROTOCOL-NOTES.md`).

/// Bits on the wire per byte on an 8N1 line: start bit, 8 data bits, stop bit.
pub const BITS_PER_BYTE: u32 = 10;

/// Duration of one byte on an 8N1 wire at `baud` (a baud rate of 0 is taken as 1), in
/// nanoseconds: `10e9 / baud`, about 520 833.3 ns at HW-FOC's
/// [`BAUD_RATE`](crate::foc::BAUD_RATE).
///
/// The one definition of byte timing: recorders and simulators that place bytes in time use it,
/// so that their timestamps agree to the last bit.
///
/// ```
/// use hwfoc::foc::BAUD_RATE;
/// use hwfoc::wire::byte_ns;
///
/// assert_eq!(byte_ns(BAUD_RATE), 1e10 / 19200.0);
/// assert!((24.0 * byte_ns(BAUD_RATE) - 12.5e6).abs() < 1e-3); // a data frame lasts 12.5 ms
/// ```
#[inline]
pub const fn byte_ns(baud: u32) -> f64 {
    // BITS_PER_BYTE * 1e9 is exactly 10e9, the constant the CLI's recorder divided.
    BITS_PER_BYTE as f64 * 1e9 / (if baud == 0 { 1 } else { baud }) as f64
}

/// First byte of every HW-FOC frame.
pub const SYNC: u8 = 0x9B;
/// Protocol version byte (byte 2) of every frame seen on real ESCs.
pub const VERSION: u8 = 0x01;

/// The 16-bit wrapping sum of `bytes`: the checksum of a data frame, and (its low byte) the check
/// byte of a device-information frame.
///
/// ```
/// // The first frame of the XRotor capture: sum 0x080D, sent as `0D 08`.
/// let frame = [0x9B, 0x16, 0x01, 0x02, 0x05, 0xC2, 0, 0, 0, 0, 0, 0, 0x00, 0xF7,
///              0xFF, 0xFF, 0xFF, 0xFF, 0xCE, 0xD1, 0x00, 0x00];
/// assert_eq!(hwfoc::wire::sum16(&frame), 0x080D);
/// ```
#[inline]
pub const fn sum16(bytes: &[u8]) -> u16 {
    // Summing into a u32 first lets the compiler vectorise; the wrap to 16 bits is exact because
    // no realistic slice (< 16 MiB) overflows a u32.
    let mut sum = 0u32;
    let mut i = 0;
    while i < bytes.len() {
        sum += bytes[i] as u32;
        i += 1;
    }
    sum as u16
}

/// The CRC-16/XMODEM lookup table (polynomial 0x1021): entry `i` is the CRC register after
/// shifting the byte `i` through a zero register. Built at compile time; 512 bytes.
const CRC16_XMODEM_TABLE: [u16; 256] = {
    let mut table = [0u16; 256];
    let mut i = 0;
    while i < 256 {
        let mut crc = (i as u16) << 8;
        let mut bit = 0;
        while bit < 8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ CRC16_XMODEM_POLY
            } else {
                crc << 1
            };
            bit += 1;
        }
        table[i] = crc;
        i += 1;
    }
    table
};

/// The generator polynomial of CRC-16/XMODEM (x^16 + x^12 + x^5 + 1, the CCITT polynomial).
const CRC16_XMODEM_POLY: u16 = 0x1021;

/// The CRC-16/XMODEM of `bytes`: polynomial 0x1021, initial value 0, no reflection, no final
/// XOR (check value 0x31C3 for `"123456789"`). The check of a DataLink V2 frame
/// ([`crate::datalink`]), table-driven, one byte per step.
///
/// ```
/// assert_eq!(hwfoc::wire::crc16_xmodem(b"123456789"), 0x31C3);
/// assert_eq!(hwfoc::wire::crc16_xmodem(&[]), 0);
/// ```
#[inline]
pub const fn crc16_xmodem(bytes: &[u8]) -> u16 {
    crc16_ccitt(0, bytes)
}

/// The CRC of `bytes` with the CCITT polynomial 0x1021, unreflected, without a final XOR, from
/// the running value `crc`: 0 starts CRC-16/XMODEM ([`crc16_xmodem`]), 0xFFFF
/// CRC-16/CCITT-FALSE (DroneCAN's transfer CRC; check value 0x29B1), and a value returned
/// goes on over more bytes.
///
/// ```
/// use hwfoc::wire::crc16_ccitt;
/// assert_eq!(crc16_ccitt(0xFFFF, b"123456789"), 0x29B1);
/// assert_eq!(crc16_ccitt(crc16_ccitt(0xFFFF, b"1234"), b"56789"), 0x29B1);
/// ```
#[inline]
pub const fn crc16_ccitt(mut crc: u16, bytes: &[u8]) -> u16 {
    let mut i = 0;
    while i < bytes.len() {
        crc = (crc << 8) ^ CRC16_XMODEM_TABLE[((crc >> 8) as u8 ^ bytes[i]) as usize];
        i += 1;
    }
    crc
}

/// The CRC-16/MODBUS lookup table (polynomial 0x8005 reflected: 0xA001): entry `i` is the CRC
/// register after shifting the byte `i` through a zero register, least significant bit first.
/// Built at compile time; 512 bytes.
const CRC16_MODBUS_TABLE: [u16; 256] = {
    let mut table = [0u16; 256];
    let mut i = 0;
    while i < 256 {
        let mut crc = i as u16;
        let mut bit = 0;
        while bit < 8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ CRC16_MODBUS_POLY_REFLECTED
            } else {
                crc >> 1
            };
            bit += 1;
        }
        table[i] = crc;
        i += 1;
    }
    table
};

/// The generator polynomial of CRC-16/MODBUS (x^16 + x^15 + x^2 + 1, 0x8005), bit-reversed for
/// the reflected (least significant bit first) register.
const CRC16_MODBUS_POLY_REFLECTED: u16 = 0xA001;

/// The CRC-16/MODBUS of `bytes`: polynomial 0x8005 reflected (0xA001), initial value 0xFFFF,
/// input and output reflected, no final XOR (check value 0x4B37 for `"123456789"`). The check
/// of every HW5 frame ([`crate::hw5`]), sent low byte first; table-driven, one byte per step.
///
/// ```
/// assert_eq!(hwfoc::wire::crc16_modbus(b"123456789"), 0x4B37);
/// assert_eq!(hwfoc::wire::crc16_modbus(&[]), 0xFFFF);
/// ```
#[inline]
pub const fn crc16_modbus(bytes: &[u8]) -> u16 {
    let mut crc = 0xFFFFu16;
    let mut i = 0;
    while i < bytes.len() {
        crc = (crc >> 8) ^ CRC16_MODBUS_TABLE[(crc as u8 ^ bytes[i]) as usize];
        i += 1;
    }
    crc
}

/// How a frame kind protects its bytes: the check bytes at the end of the frame.
///
/// Each kind names one in [`FrameKind::CHECKSUM`](crate::foc::FrameKind::CHECKSUM) (and the
/// DataLink frame of [`crate::datalink`] uses [`Checksum::Crc16Xmodem`]); the shared code computes,
/// verifies and writes it. A new kind of check is one more arm here and in the methods below.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Checksum {
    /// The 16-bit wrapping sum of every byte before the check bytes, sent low byte first
    /// (2 check bytes): data frames. Real frames do not match the CRC-16/MODBUS that one revision
    /// of the vendor document names; the sum does (`docs/PROTOCOL-NOTES.md`).
    Sum16Le,
    /// The low byte of that sum (1 check byte): device-information frames.
    Sum8,
    /// The CRC-16/XMODEM ([`crc16_xmodem`]) of every byte before the check bytes, sent low byte
    /// first (2 check bytes): DataLink V2 hub frames ([`crate::datalink`]).
    Crc16Xmodem,
    /// The CRC-16/MODBUS ([`crc16_modbus`]) of every byte before the check bytes, sent low byte
    /// first (2 check bytes): HW5 frames ([`crate::hw5`]).
    Crc16Modbus,
}

impl Checksum {
    /// Number of check bytes at the end of the frame.
    #[inline]
    pub const fn width(self) -> usize {
        match self {
            Checksum::Sum16Le | Checksum::Crc16Xmodem | Checksum::Crc16Modbus => 2,
            Checksum::Sum8 => 1,
        }
    }

    /// The check value of `covered`, the bytes of a frame before its check bytes.
    #[inline(always)]
    pub fn compute(self, covered: &[u8]) -> u16 {
        match self {
            Checksum::Sum16Le => sum16(covered),
            Checksum::Sum8 => sum16(covered) & 0xFF,
            Checksum::Crc16Xmodem => crc16_xmodem(covered),
            Checksum::Crc16Modbus => crc16_modbus(covered),
        }
    }

    /// The check value carried by `check`, the check bytes of a frame ([`Checksum::width`] of
    /// them; `None` if fewer are given).
    #[inline(always)]
    pub fn carried(self, check: &[u8]) -> Option<u16> {
        match self {
            Checksum::Sum16Le | Checksum::Crc16Xmodem | Checksum::Crc16Modbus => {
                check.first_chunk().map(|&b| u16::from_le_bytes(b))
            }
            Checksum::Sum8 => check.first().map(|&b| u16::from(b)),
        }
    }

    /// Checks the check bytes at the end of `frame` (a whole frame, nothing after it).
    ///
    /// The error carries the value computed over the bytes (`expected`) and the one the frame
    /// carries (`found`); a slice shorter than the check bytes is [`CheckError::Truncated`] (a format's frame error is made `From` it).
    #[inline(always)]
    pub fn verify(self, frame: &[u8]) -> Result<(), CheckError> {
        let truncated = CheckError::Truncated {
            needed: self.width(),
            got: frame.len(),
        };
        let Some((covered, check)) = frame
            .len()
            .checked_sub(self.width())
            .and_then(|at| frame.split_at_checked(at))
        else {
            return Err(truncated);
        };
        let expected = self.compute(covered);
        let found = self.carried(check).ok_or(truncated)?;
        if expected != found {
            return Err(CheckError::Checksum { expected, found });
        }
        Ok(())
    }

    /// Writes the check bytes at the end of `frame` (a whole frame) over the bytes before them.
    #[inline]
    pub fn seal(self, frame: &mut [u8]) {
        let Some(at) = frame.len().checked_sub(self.width()) else {
            return;
        };
        let (covered, check) = frame.split_at_mut(at);
        let value = self.compute(covered);
        match self {
            Checksum::Sum16Le | Checksum::Crc16Xmodem | Checksum::Crc16Modbus => {
                check.copy_from_slice(&value.to_le_bytes())
            }
            Checksum::Sum8 => check[0] = value as u8,
        }
    }
}

/// The value of IEEE binary16 bits (exact), as libuavcan and pydronecan convert
/// (`f32_from_f16`).
pub fn f32_from_f16(h: u16) -> f32 {
    let magic = f32::from_bits((254 - 15) << 23);
    let was_inf_nan = f32::from_bits((127 + 16) << 23);
    let mut out = f32::from_bits(u32::from(h & 0x7FFF) << 13) * magic;
    let mut u = out.to_bits();
    if out >= was_inf_nan {
        u |= 255 << 23;
    }
    u |= u32::from(h & 0x8000) << 16;
    out = f32::from_bits(u);
    out
}

/// Why a frame's check bytes do not hold ([`Checksum::verify`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CheckError {
    /// Fewer bytes than the check bytes.
    Truncated {
        /// Bytes the check bytes take.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// The check bytes do not match the bytes: the frame was corrupted on the wire.
    Checksum {
        /// Check value computed over the received bytes.
        expected: u16,
        /// Check value carried by the frame.
        found: u16,
    },
}

impl core::fmt::Display for CheckError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            CheckError::Truncated { needed, got } => {
                write!(f, "truncated: {got} bytes, the check bytes need {needed}")
            }
            CheckError::Checksum { expected, found } => write!(
                f,
                "check bytes {found:#06X} do not match the bytes' {expected:#06X}"
            ),
        }
    }
}

impl core::error::Error for CheckError {}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foc::BAUD_RATE;

    #[test]
    fn byte_ns_is_the_recorders_formula() {
        // Ten bits per byte (8N1) in nanoseconds, a baud rate of 0 taken as 1, written out.
        let written_out = |baud: u32| 10e9 / f64::from(baud.max(1));
        for baud in (0..=1_000_000)
            .step_by(7)
            .chain([19_200, 115_200, 19_332, u32::MAX])
        {
            assert_eq!(
                byte_ns(baud).to_bits(),
                written_out(baud).to_bits(),
                "{baud}"
            );
        }
        assert_eq!(byte_ns(BAUD_RATE), 10.0e9 / 19200.0);
    }

    /// CRC-16/XMODEM one bit at a time, straight from its definition.
    fn crc16_bitwise(bytes: &[u8]) -> u16 {
        let mut crc = 0u16;
        for &b in bytes {
            for bit in (0..8).rev() {
                let feedback = ((crc >> 15) ^ u16::from(b >> bit)) & 1;
                crc <<= 1;
                if feedback != 0 {
                    crc ^= 0x1021;
                }
            }
        }
        crc
    }

    #[test]
    fn crc16_xmodem_check_value_and_bitwise_reference() {
        assert_eq!(crc16_xmodem(b"123456789"), 0x31C3);
        assert_eq!(crc16_bitwise(b"123456789"), 0x31C3);
        assert_eq!(CRC16_XMODEM_TABLE[1], 0x1021);
        assert_eq!(CRC16_XMODEM_TABLE[255], 0x1EF0);
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        let mut buf = [0u8; 200];
        for len in 0..buf.len() {
            for b in buf.iter_mut() {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                *b = x as u8;
            }
            assert_eq!(
                crc16_xmodem(&buf[..len]),
                crc16_bitwise(&buf[..len]),
                "{len}"
            );
        }
        for b in 0..=255u8 {
            assert_eq!(crc16_xmodem(&[b]), crc16_bitwise(&[b]));
        }
    }

    #[test]
    fn crc16_xmodem_checksum_arm() {
        let mut frame = *b"123456789\0\0";
        Checksum::Crc16Xmodem.seal(&mut frame);
        assert_eq!(frame[9..], [0xC3, 0x31], "low byte first");
        assert_eq!(Checksum::Crc16Xmodem.width(), 2);
        assert_eq!(Checksum::Crc16Xmodem.verify(&frame), Ok(()));
        frame[0] ^= 0x80;
        assert_eq!(
            Checksum::Crc16Xmodem.verify(&frame),
            Err(CheckError::Checksum {
                expected: crc16_xmodem(&frame[..9]),
                found: 0x31C3
            })
        );
    }

    /// CRC-16/MODBUS one bit at a time, straight from its definition: the register starts at
    /// 0xFFFF, each byte is XORed into its low end and shifted out least significant bit first,
    /// with 0xA001 (0x8005 reversed) fed back on a 1.
    fn crc16_modbus_bitwise(bytes: &[u8]) -> u16 {
        let mut crc = 0xFFFFu16;
        for &b in bytes {
            crc ^= u16::from(b);
            for _ in 0..8 {
                let out = crc & 1;
                crc >>= 1;
                if out != 0 {
                    crc ^= 0xA001;
                }
            }
        }
        crc
    }

    #[test]
    fn crc16_modbus_check_value_and_bitwise_reference() {
        assert_eq!(crc16_modbus(b"123456789"), 0x4B37);
        assert_eq!(crc16_modbus_bitwise(b"123456789"), 0x4B37);
        assert_eq!(crc16_modbus(&[]), 0xFFFF);
        assert_eq!(CRC16_MODBUS_TABLE[1], 0xC0C1);
        assert_eq!(CRC16_MODBUS_TABLE[128], 0xA001);
        assert_eq!(CRC16_MODBUS_TABLE[255], 0x4040);
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut buf = [0u8; 200];
        for len in 0..buf.len() {
            for b in buf.iter_mut() {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                *b = x as u8;
            }
            assert_eq!(
                crc16_modbus(&buf[..len]),
                crc16_modbus_bitwise(&buf[..len]),
                "{len}"
            );
        }
        for b in 0..=255u8 {
            assert_eq!(crc16_modbus(&[b]), crc16_modbus_bitwise(&[b]));
        }
    }

    #[test]
    fn crc16_modbus_checksum_arm() {
        let mut frame = *b"123456789\0\0";
        Checksum::Crc16Modbus.seal(&mut frame);
        assert_eq!(frame[9..], [0x37, 0x4B], "low byte first");
        assert_eq!(Checksum::Crc16Modbus.width(), 2);
        assert_eq!(Checksum::Crc16Modbus.verify(&frame), Ok(()));
        assert_eq!(Checksum::Crc16Modbus.carried(&frame[9..]), Some(0x4B37));
        frame[8] ^= 0x01;
        assert_eq!(
            Checksum::Crc16Modbus.verify(&frame),
            Err(CheckError::Checksum {
                expected: crc16_modbus(&frame[..9]),
                found: 0x4B37
            })
        );
    }

    #[test]
    fn checksum_kinds() {
        let mut frame = [0u8; 24];
        frame[..4].copy_from_slice(&[SYNC, 0x16, VERSION, 0x02]);
        frame[4..22].fill(0xFF);
        Checksum::Sum16Le.seal(&mut frame);
        let sum = 0x9B + 0x16 + 0x01 + 0x02 + 18 * 0xFF;
        assert_eq!(frame[22..], [sum as u8, (sum >> 8) as u8]);
        assert_eq!(Checksum::Sum16Le.verify(&frame), Ok(()));
        frame[5] ^= 1;
        assert_eq!(
            Checksum::Sum16Le.verify(&frame),
            Err(CheckError::Checksum {
                expected: sum - 1,
                found: sum
            })
        );
        let mut short = [0x9B, 0x4C, 0];
        Checksum::Sum8.seal(&mut short);
        assert_eq!(short[2], 0xE7);
        assert_eq!(Checksum::Sum8.verify(&short), Ok(()));
        assert_eq!(
            Checksum::Sum16Le.verify(&[1]),
            Err(CheckError::Truncated { needed: 2, got: 1 })
        );
        assert_eq!(
            Checksum::Sum8.verify(&[]),
            Err(CheckError::Truncated { needed: 1, got: 0 })
        );
    }
}
