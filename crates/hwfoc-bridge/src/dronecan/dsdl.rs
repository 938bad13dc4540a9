//! The DSDL messages the node sends, serialised by hand: `uavcan.equipment.esc.Status`
//! (1034), `uavcan.equipment.esc.StatusExtended` (1036) and `uavcan.protocol.NodeStatus` (341),
//! from the definitions in <https://github.com/dronecan/DSDL>
//! (`uavcan/equipment/esc/1034.Status.uavcan`, `uavcan/equipment/esc/1036.StatusExtended.uavcan`,
//! `uavcan/protocol/341.NodeStatus.uavcan`).
//!
//! DSDL bit packing: fields follow each other with no padding; a field of `n` bits is its value
//! as little-endian bytes, each written most significant bit first, the last (partial) byte
//! contributing its `n % 8` low bits. Neither message has an array, so the tail array
//! optimisation does not apply; a message that does not fill its last byte is padded with zero
//! bits.
//!
//! The data type signatures are those pydronecan 1.0.27 computes from the same definitions
//! (`dronecan.uavcan.equipment.esc.Status.get_data_type_signature()`). StatusExtended (7 bytes)
//! and NodeStatus fit one CAN frame, whose transfer has no CRC: their signatures are not on the
//! wire.

/// `uavcan.equipment.esc.Status`: data type id.
pub const ESC_STATUS_ID: u16 = 1034;
/// `uavcan.equipment.esc.Status`: data type signature (seeds the transfer CRC).
pub const ESC_STATUS_SIGNATURE: u64 = 0xA9AF_28AE_A2FB_B254;
/// `uavcan.equipment.esc.Status`: serialised length, bytes (110 bits).
pub const ESC_STATUS_LEN: usize = 14;

/// `uavcan.equipment.esc.StatusExtended`: data type id.
pub const ESC_STATUS_EXTENDED_ID: u16 = 1036;
/// `uavcan.equipment.esc.StatusExtended`: data type signature.
pub const ESC_STATUS_EXTENDED_SIGNATURE: u64 = 0x02DC_203C_5096_0EDC;
/// `uavcan.equipment.esc.StatusExtended`: serialised length, bytes (56 bits).
pub const ESC_STATUS_EXTENDED_LEN: usize = 7;

/// `uavcan.protocol.NodeStatus`: data type id.
pub const NODE_STATUS_ID: u16 = 341;
/// `uavcan.protocol.NodeStatus`: data type signature.
pub const NODE_STATUS_SIGNATURE: u64 = 0x0F08_68D0_C1A7_C6F1;
/// `uavcan.protocol.NodeStatus`: serialised length, bytes (56 bits).
pub const NODE_STATUS_LEN: usize = 7;

/// The largest magnitude a float16 holds; DSDL's default (saturated) cast clamps finite values
/// to it. Infinities and NaN pass unchanged.
const F16_MAX: f32 = 65504.0;

/// `uavcan.equipment.esc.Status`: one ESC's state. Unknown values are NaN (the DSDL's rule).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EscStatus {
    /// `uint32 error_count`.
    pub error_count: u32,
    /// `float16 voltage`, V.
    pub voltage: f32,
    /// `float16 current`, A (negative while braking regeneratively).
    pub current: f32,
    /// `float16 temperature`, K.
    pub temperature: f32,
    /// `int18 rpm`: saturated to -131072..=131071.
    pub rpm: i32,
    /// `uint7 power_rating_pct`: saturated to 0..=127.
    pub power_rating_pct: u8,
    /// `uint5 esc_index`: 0..=31 (higher bits are dropped: the caller sends only 0..=31).
    pub esc_index: u8,
}

impl EscStatus {
    /// The DSDL serialisation.
    pub fn serialize(&self) -> [u8; ESC_STATUS_LEN] {
        let mut w = BitWriter::<ESC_STATUS_LEN>::new();
        w.put(u64::from(self.error_count), 32);
        w.put(u64::from(f16_bits(self.voltage)), 16);
        w.put(u64::from(f16_bits(self.current)), 16);
        w.put(u64::from(f16_bits(self.temperature)), 16);
        let rpm = self.rpm.clamp(-(1 << 17), (1 << 17) - 1);
        w.put(u64::from(rpm as u32), 18);
        w.put(u64::from(self.power_rating_pct.min(127)), 7);
        w.put(u64::from(self.esc_index), 5);
        w.finish()
    }
}

/// `uavcan.equipment.esc.StatusExtended`: what an ESC adds to its [`EscStatus`], at a lower
/// rate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EscStatusExtended {
    /// `uint7 input_pct`: the throttle command the ESC received, 0..=100 % (saturated to
    /// 0..=127).
    pub input_pct: u8,
    /// `uint7 output_pct`: what the ESC drives the motor with, 0..=100 % (saturated to 0..=127).
    pub output_pct: u8,
    /// `int9 motor_temperature_degC`: saturated to -256..=255.
    pub motor_temperature_deg_c: i16,
    /// `uint9 motor_angle`, degrees: saturated to 0..=511.
    pub motor_angle: u16,
    /// `uint19 status_flags`: manufacturer-specific flags (the low 19 bits are sent).
    pub status_flags: u32,
    /// `uint5 esc_index`: 0..=31 (higher bits are dropped: the caller sends only 0..=31).
    pub esc_index: u8,
}

impl EscStatusExtended {
    /// The DSDL serialisation.
    pub fn serialize(&self) -> [u8; ESC_STATUS_EXTENDED_LEN] {
        let mut w = BitWriter::<ESC_STATUS_EXTENDED_LEN>::new();
        w.put(u64::from(self.input_pct.min(127)), 7);
        w.put(u64::from(self.output_pct.min(127)), 7);
        let t = self.motor_temperature_deg_c.clamp(-256, 255);
        w.put(u64::from(t as u16), 9);
        w.put(u64::from(self.motor_angle.min(511)), 9);
        w.put(u64::from(self.status_flags), 19);
        w.put(u64::from(self.esc_index), 5);
        w.finish()
    }
}

/// `uavcan.protocol.NodeStatus.health`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum Health {
    /// `HEALTH_OK`.
    Ok = 0,
    /// `HEALTH_WARNING`.
    Warning = 1,
    /// `HEALTH_ERROR`.
    Error = 2,
    /// `HEALTH_CRITICAL`.
    Critical = 3,
}

/// `uavcan.protocol.NodeStatus.mode`: `MODE_OPERATIONAL`.
pub const MODE_OPERATIONAL: u8 = 0;

/// `uavcan.protocol.NodeStatus`: the node's heartbeat.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NodeStatus {
    /// `uint32 uptime_sec`.
    pub uptime_sec: u32,
    /// `uint2 health`.
    pub health: Health,
    /// `uint3 mode`.
    pub mode: u8,
    /// `uint3 sub_mode`.
    pub sub_mode: u8,
    /// `uint16 vendor_specific_status_code`.
    pub vendor_specific_status_code: u16,
}

impl NodeStatus {
    /// The DSDL serialisation.
    pub fn serialize(&self) -> [u8; NODE_STATUS_LEN] {
        let mut w = BitWriter::<NODE_STATUS_LEN>::new();
        w.put(u64::from(self.uptime_sec), 32);
        w.put(self.health as u64, 2);
        w.put(u64::from(self.mode), 3);
        w.put(u64::from(self.sub_mode), 3);
        w.put(u64::from(self.vendor_specific_status_code), 16);
        w.finish()
    }
}

/// IEEE 754 binary16 bits of `v`, rounded to nearest (the `half` crate), finite values
/// saturated to ±65504 as DSDL's saturated cast asks.
pub fn f16_bits(v: f32) -> u16 {
    let v = if v.is_finite() {
        v.clamp(-F16_MAX, F16_MAX)
    } else {
        v
    };
    half::f16::from_f32(v).to_bits()
}

/// Writes DSDL fields into `N` bytes.
struct BitWriter<const N: usize> {
    buf: [u8; N],
    bit: usize,
}

impl<const N: usize> BitWriter<N> {
    fn new() -> Self {
        BitWriter {
            buf: [0; N],
            bit: 0,
        }
    }

    /// The `width` low bits of `value` (at most 64).
    fn put(&mut self, value: u64, width: u32) {
        let mut left = width;
        for byte in value.to_le_bytes() {
            if left == 0 {
                break;
            }
            let n = left.min(8);
            let byte = if n == 8 { byte } else { byte & ((1 << n) - 1) };
            for i in (0..n).rev() {
                if (byte >> i) & 1 == 1 {
                    self.buf[self.bit / 8] |= 0x80 >> (self.bit % 8);
                }
                self.bit += 1;
            }
            left -= n;
        }
    }

    fn finish(self) -> [u8; N] {
        debug_assert!(self.bit.div_ceil(8) == N, "{} bits in {N} bytes", self.bit);
        self.buf
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Checked by hand from the DSDL: 7 | 16.5 V = 0x4C20 | -2.25 A = 0xC080 | 313.15 K =
    /// 0x5CE5 | rpm -1234 = 0x3FB2E (18 bits: 2E FB, then 0b11) | 55 = 0b0110111 | 3 = 0b00011:
    /// byte 12 = 11 011011, byte 13 = 1 00011 00. The same bytes as pydronecan 1.0.27's.
    #[test]
    fn esc_status_bytes() {
        let s = EscStatus {
            error_count: 7,
            voltage: 16.5,
            current: -2.25,
            temperature: 273.15 + 40.0,
            rpm: -1234,
            power_rating_pct: 55,
            esc_index: 3,
        };
        assert_eq!(
            s.serialize(),
            [
                0x07, 0x00, 0x00, 0x00, 0x20, 0x4C, 0x80, 0xC0, 0xE5, 0x5C, 0x2E, 0xFB, 0xDB, 0x8C
            ]
        );
    }

    #[test]
    fn esc_status_saturates_and_nan() {
        let s = EscStatus {
            error_count: 0xDEAD_BEEF,
            voltage: f32::NAN,
            current: 1.0e6,
            temperature: f32::NAN,
            rpm: 500_000,
            power_rating_pct: 200,
            esc_index: 31,
        };
        let b = s.serialize();
        assert_eq!(&b[..4], &[0xEF, 0xBE, 0xAD, 0xDE]);
        assert_eq!(u16::from_le_bytes([b[4], b[5]]), 0x7E00); // NaN
        assert_eq!(u16::from_le_bytes([b[6], b[7]]), 0x7BFF); // 65504
        // rpm 131071 = 0x1FFFF: FF FF then 0b01; power 127; index 31; two bits of padding
        // (pydronecan: 7F FC).
        assert_eq!(&b[10..], &[0xFF, 0xFF, 0x7F, 0xFC]);
    }

    /// pydronecan 1.0.27: StatusExtended(input_pct=55, output_pct=100, motor_temperature_degC=-40,
    /// motor_angle=0, status_flags=0x5A5A5, esc_index=3) is 6f 93 62 00 a5 a5 a3 (the payload of
    /// its single frame `6f936200a5a5a3c0`).
    #[test]
    fn esc_status_extended_bytes() {
        let s = EscStatusExtended {
            input_pct: 55,
            output_pct: 100,
            motor_temperature_deg_c: -40,
            motor_angle: 0,
            status_flags: 0x5A5A5,
            esc_index: 3,
        };
        assert_eq!(s.serialize(), [0x6F, 0x93, 0x62, 0x00, 0xA5, 0xA5, 0xA3]);
    }

    /// pydronecan: NodeStatus(uptime_sec=123456, health=1, mode=0, sub_mode=0,
    /// vendor_specific_status_code=0xABCD) is 40 e2 01 00 40 cd ab.
    #[test]
    fn node_status_bytes() {
        let s = NodeStatus {
            uptime_sec: 123_456,
            health: Health::Warning,
            mode: MODE_OPERATIONAL,
            sub_mode: 0,
            vendor_specific_status_code: 0xABCD,
        };
        assert_eq!(s.serialize(), [0x40, 0xE2, 0x01, 0x00, 0x40, 0xCD, 0xAB]);
    }
}
