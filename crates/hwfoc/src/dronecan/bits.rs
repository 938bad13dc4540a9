//! DSDL bit packing (DroneCAN specification, "Data serialization"; pydronecan's
//! `transport.le_from_be_bits`): fields follow each other with no padding; a field of `n` bits
//! is its value's little-endian bytes, each written most significant bit first, the last
//! (partial) byte contributing its `n % 8` low bits. A transfer's last byte is padded with zero
//! bits. Integers are cast with DSDL's default, saturated cast (a value beyond the field's
//! range becomes its nearest end), float16 with pydronecan's conversion
//! ([`f16_from_f32`], [`f32_from_f16`]).

/// Writes fields into a byte buffer. Bits beyond the buffer are dropped (never a panic); the
/// callers size their buffers from the type's bit length.
pub(crate) struct BitWriter<'a> {
    buf: &'a mut [u8],
    bit: usize,
}

impl<'a> BitWriter<'a> {
    /// A writer at the start of `buf`, which it clears.
    pub(crate) fn new(buf: &'a mut [u8]) -> Self {
        buf.fill(0);
        BitWriter { buf, bit: 0 }
    }

    /// The `width` (at most 64) low bits of `value`.
    pub(crate) fn put(&mut self, value: u64, width: u32) {
        let mut left = width;
        for byte in value.to_le_bytes() {
            if left == 0 {
                break;
            }
            let n = left.min(8);
            for i in (0..n).rev() {
                if (byte >> i) & 1 == 1
                    && let Some(b) = self.buf.get_mut(self.bit / 8)
                {
                    *b |= 0x80 >> (self.bit % 8);
                }
                self.bit += 1;
            }
            left -= n;
        }
    }

    /// Bytes written (the last one padded).
    pub(crate) fn len(&self) -> usize {
        self.bit.div_ceil(8)
    }
}

/// Reads fields from a byte slice; bits beyond it read as 0 (the callers check lengths first).
pub(crate) struct BitReader<'a> {
    buf: &'a [u8],
    bit: usize,
}

impl<'a> BitReader<'a> {
    pub(crate) fn new(buf: &'a [u8]) -> Self {
        BitReader { buf, bit: 0 }
    }

    /// The next `width` (at most 64) bits as an unsigned value.
    pub(crate) fn get(&mut self, width: u32) -> u64 {
        let mut out = 0u64;
        let mut left = width;
        let mut shift = 0;
        while left > 0 {
            let n = left.min(8);
            let mut byte = 0u64;
            for _ in 0..n {
                let bit = self
                    .buf
                    .get(self.bit / 8)
                    .map_or(0, |b| (b >> (7 - self.bit % 8)) & 1);
                byte = (byte << 1) | u64::from(bit);
                self.bit += 1;
            }
            out |= byte << shift;
            shift += 8;
            left -= n;
        }
        out
    }

    /// Bits read so far.
    #[cfg(test)]
    pub(crate) fn bits(&self) -> usize {
        self.bit
    }
}

/// A DSDL primitive held in a Rust type: its bits on the wire (saturated to the field's width)
/// and back.
pub(crate) trait Field: Copy {
    fn to_raw(self, width: u32) -> u64;
    fn from_raw(raw: u64, width: u32) -> Self;
}

const fn unsigned_max(width: u32) -> u64 {
    if width >= 64 {
        u64::MAX
    } else {
        (1 << width) - 1
    }
}

macro_rules! unsigned_field {
    ($($t:ty),*) => {$(
        impl Field for $t {
            fn to_raw(self, width: u32) -> u64 {
                (self as u64).min(unsigned_max(width))
            }
            fn from_raw(raw: u64, _width: u32) -> Self {
                raw as $t
            }
        }
    )*};
}
unsigned_field!(u8, u16, u32);

macro_rules! signed_field {
    ($($t:ty),*) => {$(
        impl Field for $t {
            fn to_raw(self, width: u32) -> u64 {
                let max = (1i64 << (width - 1)) - 1;
                let v = (self as i64).clamp(-max - 1, max);
                (v as u64) & unsigned_max(width)
            }
            fn from_raw(raw: u64, width: u32) -> Self {
                // sign-extend from `width` bits
                let shift = 64 - width;
                (((raw << shift) as i64) >> shift) as $t
            }
        }
    )*};
}
signed_field!(i16, i32);

impl Field for bool {
    fn to_raw(self, _width: u32) -> u64 {
        u64::from(self)
    }
    fn from_raw(raw: u64, _width: u32) -> Self {
        raw != 0
    }
}

/// A static array of two bytes (`uint8[2]`): the same bits as their little-endian `uint16`.
impl Field for [u8; 2] {
    fn to_raw(self, _width: u32) -> u64 {
        u64::from(u16::from_le_bytes(self))
    }
    fn from_raw(raw: u64, _width: u32) -> Self {
        (raw as u16).to_le_bytes()
    }
}

/// `float16`: saturated to ±65504 as DSDL's default cast (pydronecan's `cast`: infinities too),
/// NaN kept; converted by [`f16_from_f32`].
impl Field for f32 {
    fn to_raw(self, _width: u32) -> u64 {
        u64::from(f16_from_f32(saturate_f16(self)))
    }
    fn from_raw(raw: u64, _width: u32) -> Self {
        f32_from_f16(raw as u16)
    }
}

/// The largest magnitude of a float16.
pub const F16_MAX: f32 = 65504.0;

/// DSDL's saturated cast to float16's range: values beyond ±65504 (infinities included, as
/// pydronecan's `cast` does) become ±65504; NaN passes.
pub fn saturate_f16(v: f32) -> f32 {
    v.clamp(-F16_MAX, F16_MAX)
}

/// IEEE binary16 bits of `v`, as libuavcan and pydronecan convert (`f16_from_f32`): rounded to
/// nearest with ties away from zero, overflow to infinity, NaN to `0x7FFF` (with the sign of
/// `v`). No saturation here: [`saturate_f16`] first for DSDL's cast.
///
/// ```
/// use hwfoc::dronecan::{f16_from_f32, f32_from_f16};
/// assert_eq!(f16_from_f32(16.5), 0x4C20);
/// assert_eq!(f16_from_f32(f32::NAN), 0x7FFF);
/// assert_eq!(f16_from_f32(1.0e6), 0x7C00);
/// assert_eq!(f32_from_f16(0xC080), -2.25);
/// ```
pub fn f16_from_f32(v: f32) -> u16 {
    const F32_INFTY: u32 = 255 << 23;
    const F16_INFTY: u32 = 31 << 23;
    const ROUND_MASK: u32 = !0xFFF;
    let magic = f32::from_bits(15 << 23);
    let mut u = v.to_bits();
    let sign = u & 0x8000_0000;
    u ^= sign;
    let out = if u >= F32_INFTY {
        if u > F32_INFTY { 0x7FFF } else { 0x7C00 }
    } else {
        u &= ROUND_MASK;
        u = (f32::from_bits(u) * magic).to_bits();
        u = u.wrapping_sub(ROUND_MASK);
        if u > F16_INFTY {
            u = F16_INFTY;
        }
        (u >> 13) & 0xFFFF
    };
    (out | (sign >> 16)) as u16
}

pub use crate::wire::f32_from_f16;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_as_the_bridge_and_pydronecan() {
        // esc.Status from the bridge's test (pydronecan's bytes): 7 | 16.5 V | -2.25 A |
        // 313.15 K | rpm -1234 (int18) | 55 (uint7) | 3 (uint5).
        let mut buf = [0u8; 14];
        let mut w = BitWriter::new(&mut buf);
        w.put(7, 32);
        w.put(f32::to_raw(16.5, 16), 16);
        w.put(f32::to_raw(-2.25, 16), 16);
        w.put(f32::to_raw(313.15, 16), 16);
        w.put(i32::to_raw(-1234, 18), 18);
        w.put(u8::to_raw(55, 7), 7);
        w.put(u8::to_raw(3, 5), 5);
        assert_eq!(w.len(), 14);
        assert_eq!(
            buf,
            [
                0x07, 0x00, 0x00, 0x00, 0x20, 0x4C, 0x80, 0xC0, 0xE5, 0x5C, 0x2E, 0xFB, 0xDB, 0x8C
            ]
        );
        let mut r = BitReader::new(&buf);
        assert_eq!(r.get(32), 7);
        assert_eq!(f32::from_raw(r.get(16), 16), 16.5);
        assert_eq!(f32::from_raw(r.get(16), 16), -2.25);
        assert_eq!(r.get(16), 0x5CE5);
        assert_eq!(i32::from_raw(r.get(18), 18), -1234);
        assert_eq!(r.get(7), 55);
        assert_eq!(r.get(5), 3);
        assert_eq!(r.bits(), 110);
    }

    #[test]
    fn saturation() {
        assert_eq!(u8::to_raw(200, 7), 127);
        assert_eq!(u32::to_raw(u32::MAX, 19), 0x7FFFF);
        assert_eq!(i32::to_raw(500_000, 18), 0x1FFFF);
        assert_eq!(i32::to_raw(-500_000, 18), 0x20000);
        assert_eq!(i16::from_raw(0x1FF, 9), -1);
        assert_eq!(i16::to_raw(-300, 9), 0x100);
        assert_eq!(f32::to_raw(f32::INFINITY, 16), 0x7BFF);
        assert_eq!(f32::to_raw(f32::NEG_INFINITY, 16), 0xFBFF);
        assert_eq!(f32::to_raw(f32::NAN, 16), 0x7FFF);
    }

    #[test]
    fn f16_round_trips_every_value() {
        for h in 0..=u16::MAX {
            let v = f32_from_f16(h);
            if v.is_nan() {
                assert_eq!(f16_from_f32(v) & 0x8000, h & 0x8000);
                continue;
            }
            assert_eq!(f16_from_f32(v), h, "{h:04X} {v}");
        }
        // ties away from zero: 1 + 2^-11 lies halfway between 1 and 1 + 2^-10
        assert_eq!(f16_from_f32(1.0 + 1.0 / 2048.0), 0x3C01);
        assert_eq!(f16_from_f32(65520.0), 0x7C00);
        assert_eq!(f16_from_f32(-0.0), 0x8000);
    }
}
