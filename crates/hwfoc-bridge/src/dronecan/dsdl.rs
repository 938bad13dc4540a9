//! The DSDL messages the node sends: `uavcan.equipment.esc.Status` (1034),
//! `uavcan.equipment.esc.StatusExtended` (1036) and `uavcan.protocol.NodeStatus` (341), the
//! codec's types ([`hwfoc::dronecan`]: their data type ids and signatures are
//! [`hwfoc::dronecan::Kind`]'s, their serialisation [`DataType::encode_into`], checked against
//! pydronecan's own bytes in `testdata/dronecan/vectors.txt`). What is here is only what the
//! codec leaves as plain integers: NodeStatus's health and mode values.
//!
//! float16 fields (esc.Status's voltage, current, temperature) are the codec's conversion,
//! pydronecan's and libuavcan's: rounded to nearest with ties away from zero, saturated to
//! ±65504 (infinities too, DSDL's default cast), NaN sent as `0x7FFF`.

pub use hwfoc::dronecan::{DataType, EscStatus, EscStatusExtended, NodeStatus};

/// `uavcan.protocol.NodeStatus.health` ([`NodeStatus::health`] is `health as u8`).
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use hwfoc::dronecan::MAX_PAYLOAD_LEN;

    /// The DSDL serialisation of `m`, as the output sends it.
    fn bytes<T: DataType>(m: &T) -> Vec<u8> {
        let mut out = [0u8; MAX_PAYLOAD_LEN];
        let n = m.encode_into(&mut out);
        out[..n].to_vec()
    }

    /// The esc.Status of the tests that compare with pydronecan's bytes and frames.
    pub(crate) fn example_esc_status() -> EscStatus {
        EscStatus {
            error_count: 7,
            voltage: 16.5,
            current: -2.25,
            temperature: 273.15 + 40.0,
            rpm: -1234,
            power_rating_pct: 55,
            esc_index: 3,
        }
    }

    /// Checked by hand from the DSDL: 7 | 16.5 V = 0x4C20 | -2.25 A = 0xC080 | 313.15 K =
    /// 0x5CE5 | rpm -1234 = 0x3FB2E (18 bits: 2E FB, then 0b11) | 55 = 0b0110111 | 3 = 0b00011:
    /// byte 12 = 11 011011, byte 13 = 1 00011 00. The same bytes as pydronecan 1.0.27's.
    #[test]
    fn esc_status_bytes() {
        let s = example_esc_status();
        assert_eq!(
            bytes(&s),
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
        let b = bytes(&s);
        assert_eq!(&b[..4], &[0xEF, 0xBE, 0xAD, 0xDE]);
        // NaN: 0x7FFF, pydronecan's (and libuavcan's) f16_from_f32; it was 0x7E00, the `half`
        // crate's, before the output used the codec's conversion. Both decode as NaN.
        assert_eq!(u16::from_le_bytes([b[4], b[5]]), 0x7FFF);
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
        assert_eq!(bytes(&s), [0x6F, 0x93, 0x62, 0x00, 0xA5, 0xA5, 0xA3]);
    }

    /// pydronecan: NodeStatus(uptime_sec=123456, health=1, mode=0, sub_mode=0,
    /// vendor_specific_status_code=0xABCD) is 40 e2 01 00 40 cd ab.
    #[test]
    fn node_status_bytes() {
        let s = NodeStatus {
            uptime_sec: 123_456,
            health: Health::Warning as u8,
            mode: MODE_OPERATIONAL,
            sub_mode: 0,
            vendor_specific_status_code: 0xABCD,
        };
        assert_eq!(bytes(&s), [0x40, 0xE2, 0x01, 0x00, 0x40, 0xCD, 0xAB]);
    }
}
