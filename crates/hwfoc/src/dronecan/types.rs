//! The DSDL data types, field by field as pydronecan 1.0.27 ships them
//! (`dronecan/dsdl_specs/com/hobbywing/esc/*.uavcan`, `uavcan/equipment/esc/1034.Status.uavcan`,
//! `1036.StatusExtended.uavcan`, `uavcan/protocol/341.NodeStatus.uavcan`). Rust field names are
//! the DSDL's in snake case (`MOS_T` is `mos_t`, `MSG_ID` is `msg_id`). Integers wider on the
//! Rust side than on the wire are saturated when encoded, as DSDL's default cast does.

use super::bits::{BitReader, BitWriter, Field};
use super::kind::{DataType, Kind, MAX_PAYLOAD_LEN, PayloadError};

fn check_len<T: DataType>(payload: &[u8]) -> Result<(), PayloadError> {
    if (T::MIN_LEN..=T::MAX_LEN).contains(&payload.len()) {
        Ok(())
    } else {
        Err(PayloadError {
            kind: T::KIND,
            len: payload.len(),
        })
    }
}

macro_rules! fixed {
    ($(
        $(#[$doc:meta])*
        $name:ident {
            $( $(#[$fdoc:meta])* $field:ident: $ty:ty = $bits:literal, )*
        }
    )*) => {$(
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Default)]
        pub struct $name {
            $( $(#[$fdoc])* pub $field: $ty, )*
        }

        impl $name {
            /// Bits on the wire.
            pub const BITS: usize = 0 $(+ $bits)*;
        }

        impl DataType for $name {
            const KIND: Kind = Kind::$name;
            const MIN_LEN: usize = Self::BITS.div_ceil(8);
            const MAX_LEN: usize = Self::BITS.div_ceil(8);

            #[allow(unused_mut, unused_variables)]
            fn encode_into(&self, out: &mut [u8; MAX_PAYLOAD_LEN]) -> usize {
                let mut w = BitWriter::new(&mut out[..]);
                $( w.put(Field::to_raw(self.$field, $bits), $bits); )*
                Self::MAX_LEN
            }

            #[allow(unused_mut, unused_variables)]
            fn decode(payload: &[u8]) -> Result<Self, PayloadError> {
                check_len::<Self>(payload)?;
                let mut r = BitReader::new(payload);
                Ok($name { $( $field: Field::from_raw(r.get($bits), $bits), )* })
            }
        }
    )*};
}

fixed! {
    /// `com.hobbywing.esc.StatusMsg1` (20050), 6 bytes, at up to 500 Hz.
    StatusMsg1 {
        /// `uint16 rpm`: the motor's rpm as the ESC reports it (mechanical or electrical is not
        /// documented).
        rpm: u16 = 16,
        /// `uint16 pwm`: output throttle, nominally 0-1000 (inferred from PX4's driver).
        pwm: u16 = 16,
        /// `uint16 status`: bit 14 = turning counter-clockwise ([`StatusMsg1::STATUS_CCW`]);
        /// the other bits are not documented.
        status: u16 = 16,
    }

    /// `com.hobbywing.esc.StatusMsg2` (20051), 5 bytes.
    StatusMsg2 {
        /// `int16 input_voltage`, 0.1 V.
        input_voltage: i16 = 16,
        /// `int16 current`, 0.1 A.
        current: i16 = 16,
        /// `uint8 temperature`, degC.
        temperature: u8 = 8,
    }

    /// `com.hobbywing.esc.StatusMsg3` (20052), 3 bytes.
    StatusMsg3 {
        /// `uint8 MOS_T`: MOSFET temperature, degC.
        mos_t: u8 = 8,
        /// `uint8 CAP_T`: capacitor temperature, degC.
        cap_t: u8 = 8,
        /// `uint8 Motor_T`: motor temperature, degC.
        motor_t: u8 = 8,
    }

    /// `uavcan.protocol.NodeStatus` (341), 7 bytes: every node's heartbeat.
    NodeStatus {
        /// `uint32 uptime_sec`.
        uptime_sec: u32 = 32,
        /// `uint2 health`: 0 OK, 1 warning, 2 error, 3 critical.
        health: u8 = 2,
        /// `uint3 mode`: 0 operational, 1 initialisation, 2 maintenance, 3 software update,
        /// 7 offline.
        mode: u8 = 3,
        /// `uint3 sub_mode`.
        sub_mode: u8 = 3,
        /// `uint16 vendor_specific_status_code`.
        vendor_specific_status_code: u16 = 16,
    }

    /// `uavcan.equipment.esc.Status` (1034), 14 bytes (a multi-frame transfer): the standard
    /// ESC status. Unknown values are NaN.
    EscStatus {
        /// `uint32 error_count`.
        error_count: u32 = 32,
        /// `float16 voltage`, V.
        voltage: f32 = 16,
        /// `float16 current`, A (negative when braking regeneratively).
        current: f32 = 16,
        /// `float16 temperature`, K.
        temperature: f32 = 16,
        /// `int18 rpm`.
        rpm: i32 = 18,
        /// `uint7 power_rating_pct`, 0-127 %.
        power_rating_pct: u8 = 7,
        /// `uint5 esc_index`, 0-31.
        esc_index: u8 = 5,
    }

    /// `uavcan.equipment.esc.StatusExtended` (1036), 7 bytes (the definition pydronecan ships
    /// under `uavcan/equipment/esc`, the same as ArduPilot's).
    EscStatusExtended {
        /// `uint7 input_pct`: throttle command received, 0-100 %.
        input_pct: u8 = 7,
        /// `uint7 output_pct`: output to the motor, 0-100 %.
        output_pct: u8 = 7,
        /// `int9 motor_temperature_degC`, -256..=255.
        motor_temperature_deg_c: i16 = 9,
        /// `uint9 motor_angle`, degrees.
        motor_angle: u16 = 9,
        /// `uint19 status_flags`: manufacturer-specific.
        status_flags: u32 = 19,
        /// `uint5 esc_index`.
        esc_index: u8 = 5,
    }

    /// `com.hobbywing.esc.SetID` (210) request: give the ESC a node id and throttle channel.
    SetIdRequest {
        /// `uint8 node_id`.
        node_id: u8 = 8,
        /// `uint8 throttle_channel` (1-based).
        throttle_channel: u8 = 8,
    }

    /// `com.hobbywing.esc.SetID` (210) response.
    SetIdResponse {
        /// `uint8 node_id`.
        node_id: u8 = 8,
        /// `uint8 throttle_channel`.
        throttle_channel: u8 = 8,
    }

    /// `com.hobbywing.esc.SetBaud` (211) request.
    SetBaudRequest {
        /// `uint8 baud`: 0 = 1 Mbit/s, 1 = 500k, 2 = 250k, 3 = 200k, 4 = 100k, 5 = 50k
        /// ([`SetBaudRequest::BITRATES`]).
        baud: u8 = 8,
    }

    /// `com.hobbywing.esc.SetBaud` (211) response: empty.
    SetBaudResponse {}

    /// `com.hobbywing.esc.SetLED` (212) request.
    SetLedRequest {
        /// `uint8 option`: 1 = save.
        option: u8 = 8,
        /// `uint8 color`: bits R = 4, G = 2, B = 1.
        color: u8 = 8,
        /// `uint8 blink`: 0 off, 1, 2 or 5 Hz.
        blink: u8 = 8,
    }

    /// `com.hobbywing.esc.SetLED` (212) response.
    SetLedResponse {
        /// `uint8 option`.
        option: u8 = 8,
        /// `uint8 color`.
        color: u8 = 8,
        /// `uint8 blink`.
        blink: u8 = 8,
    }

    /// `com.hobbywing.esc.SetDirection` (213) request.
    SetDirectionRequest {
        /// `uint8 direction`: 0 clockwise, 1 counter-clockwise, 255 query.
        direction: u8 = 8,
    }

    /// `com.hobbywing.esc.SetDirection` (213) response.
    SetDirectionResponse {
        /// `uint8 direction`: 0 clockwise, 1 counter-clockwise.
        direction: u8 = 8,
    }

    /// `com.hobbywing.esc.SetReportingFrequency` (214) request.
    SetReportingFrequencyRequest {
        /// `uint8 option`: 0 read, 1 write.
        option: u8 = 8,
        /// `uint16 MSG_ID`: the message's data type id (20050-20052).
        msg_id: u16 = 16,
        /// `uint8 rate`: 1..=9 = 500, 250, 200, 100, 50, 20, 10, 1, 0 Hz
        /// ([`SetReportingFrequencyRequest::RATES_HZ`]).
        rate: u8 = 8,
    }

    /// `com.hobbywing.esc.SetReportingFrequency` (214) response.
    SetReportingFrequencyResponse {
        /// `uint8 option`.
        option: u8 = 8,
        /// `uint16 MSG_ID`.
        msg_id: u16 = 16,
        /// `uint8 rate`.
        rate: u8 = 8,
    }

    /// `com.hobbywing.esc.SetThrottleSource` (215) request.
    SetThrottleSourceRequest {
        /// `uint8 source`: 0 CAN, 1 PWM.
        source: u8 = 8,
    }

    /// `com.hobbywing.esc.SetThrottleSource` (215) response.
    SetThrottleSourceResponse {
        /// `uint8 source`: 0 CAN, 1 PWM.
        source: u8 = 8,
    }

    /// `com.hobbywing.esc.SelfTest` (216) request: empty.
    SelfTestRequest {}

    /// `com.hobbywing.esc.SelfTest` (216) response.
    SelfTestResponse {
        /// `uint8 status`: 0 pass, 1 fail.
        status: u8 = 8,
    }

    /// `com.hobbywing.esc.SetAngle` (217) request.
    SetAngleRequest {
        /// `uint8 option`.
        option: u8 = 8,
        /// `uint16 angle`.
        angle: u16 = 16,
    }

    /// `com.hobbywing.esc.GetMaintenanceInformation` (241) request.
    GetMaintenanceInformationRequest {
        /// `uint8 option`: 1 = clear.
        option: u8 = 8,
    }

    /// `com.hobbywing.esc.GetMaintenanceInformation` (241) response.
    GetMaintenanceInformationResponse {
        /// `uint32 total_rotation_time_min`.
        total_rotation_time_min: u32 = 32,
        /// `uint24 time_since_maintainence_min` (the DSDL's spelling).
        time_since_maintenance_min: u32 = 24,
    }

    /// `com.hobbywing.esc.GetMajorConfig` (242) request.
    GetMajorConfigRequest {
        /// `uint8 option`.
        option: u8 = 8,
    }

    /// `com.hobbywing.esc.GetMajorConfig` (242) response: the ESC's settings in 7 bytes.
    GetMajorConfigResponse {
        /// `bool direction`: counter-clockwise.
        direction: bool = 1,
        /// `bool throttle_source`: PWM.
        throttle_source: bool = 1,
        /// `uint6 throttle_channel`.
        throttle_channel: u8 = 6,
        /// `uint5 led_status`.
        led_status: u8 = 5,
        /// `uint3 led_color`.
        led_color: u8 = 3,
        /// `uint4 MSG2_rate`.
        msg2_rate: u8 = 4,
        /// `uint4 MSG1_rate`.
        msg1_rate: u8 = 4,
        /// `uint16 positioning_angle`.
        positioning_angle: u16 = 16,
        /// `uint8[2] reserved`.
        reserved: [u8; 2] = 16,
    }
}

impl StatusMsg1 {
    /// The bit of [`StatusMsg1::status`] set while the motor turns counter-clockwise (the
    /// DroneCAN GUI tool's Hobbywing panel).
    pub const STATUS_CCW: u16 = 1 << 14;

    /// Whether the status word says counter-clockwise.
    pub const fn counter_clockwise(&self) -> bool {
        self.status & Self::STATUS_CCW != 0
    }
}

impl SetBaudRequest {
    /// The bit rate of each code of [`SetBaudRequest::baud`], bit/s.
    pub const BITRATES: [u32; 6] = [1_000_000, 500_000, 250_000, 200_000, 100_000, 50_000];
}

impl SetReportingFrequencyRequest {
    /// The rate of each code 1..=9 of [`SetReportingFrequencyRequest::rate`] (index
    /// `code - 1`), Hz.
    pub const RATES_HZ: [u16; 9] = [500, 250, 200, 100, 50, 20, 10, 1, 0];
}

/// `com.hobbywing.esc.GetEscID` (20013): `uint8[<=3] payload`, a tail array (no length on the
/// wire: the transfer's length is the array's). A controller broadcasts `[0]` to ask; each
/// ESC answers `[node_id, throttle_channel]` (channel 1-based).
///
/// ```
/// use hwfoc::dronecan::GetEscId;
/// assert_eq!(GetEscId::REQUEST.payload(), &[0]);
/// let answer = GetEscId::answer(5, 3);
/// assert_eq!(answer.as_answer(), Some((5, 3)));
/// assert_eq!(GetEscId::new(&[1, 2, 3, 4]), None);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct GetEscId {
    bytes: [u8; 3],
    len: u8,
}

impl GetEscId {
    /// The request ArduPilot broadcasts: `[0]`.
    pub const REQUEST: GetEscId = GetEscId {
        bytes: [0; 3],
        len: 1,
    };

    /// A GetEscID of up to 3 bytes (`None` if longer).
    pub fn new(payload: &[u8]) -> Option<GetEscId> {
        let mut bytes = [0u8; 3];
        bytes.get_mut(..payload.len())?.copy_from_slice(payload);
        Some(GetEscId {
            bytes,
            len: payload.len() as u8,
        })
    }

    /// An ESC's answer: `[node_id, throttle_channel]`.
    pub const fn answer(node_id: u8, throttle_channel: u8) -> GetEscId {
        GetEscId {
            bytes: [node_id, throttle_channel, 0],
            len: 2,
        }
    }

    /// The array.
    pub fn payload(&self) -> &[u8] {
        &self.bytes[..usize::from(self.len).min(3)]
    }

    /// `(node_id, throttle_channel)` if this is an answer (two bytes).
    pub fn as_answer(&self) -> Option<(u8, u8)> {
        match *self.payload() {
            [node, channel] => Some((node, channel)),
            _ => None,
        }
    }
}

impl DataType for GetEscId {
    const KIND: Kind = Kind::GetEscId;
    const MIN_LEN: usize = 0;
    const MAX_LEN: usize = 3;

    fn encode_into(&self, out: &mut [u8; MAX_PAYLOAD_LEN]) -> usize {
        let p = self.payload();
        out.fill(0);
        out[..p.len()].copy_from_slice(p);
        p.len()
    }

    fn decode(payload: &[u8]) -> Result<Self, PayloadError> {
        check_len::<Self>(payload)?;
        GetEscId::new(payload).ok_or(PayloadError {
            kind: Kind::GetEscId,
            len: payload.len(),
        })
    }
}

/// `com.hobbywing.esc.SetAngle` (217) response: `uint8 option`, `uint16[<=2] angle` (a tail
/// array: 1, 3 or 5 bytes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SetAngleResponse {
    /// `uint8 option`.
    pub option: u8,
    angle: [u16; 2],
    len: u8,
}

impl SetAngleResponse {
    /// A response with up to two angles (`None` if more).
    pub fn new(option: u8, angles: &[u16]) -> Option<SetAngleResponse> {
        let mut angle = [0u16; 2];
        angle.get_mut(..angles.len())?.copy_from_slice(angles);
        Some(SetAngleResponse {
            option,
            angle,
            len: angles.len() as u8,
        })
    }

    /// `uint16[<=2] angle`.
    pub fn angles(&self) -> &[u16] {
        &self.angle[..usize::from(self.len).min(2)]
    }
}

impl DataType for SetAngleResponse {
    const KIND: Kind = Kind::SetAngleResponse;
    const MIN_LEN: usize = 1;
    const MAX_LEN: usize = 5;

    fn encode_into(&self, out: &mut [u8; MAX_PAYLOAD_LEN]) -> usize {
        let mut w = BitWriter::new(&mut out[..]);
        w.put(u64::from(self.option), 8);
        for &a in self.angles() {
            w.put(u64::from(a), 16);
        }
        w.len()
    }

    fn decode(payload: &[u8]) -> Result<Self, PayloadError> {
        let err = PayloadError {
            kind: Kind::SetAngleResponse,
            len: payload.len(),
        };
        check_len::<Self>(payload)?;
        if payload.len().is_multiple_of(2) {
            return Err(err);
        }
        let mut r = BitReader::new(payload);
        let option = r.get(8) as u8;
        let mut angle = [0u16; 2];
        let n = (payload.len() - 1) / 2;
        for a in angle.iter_mut().take(n) {
            *a = r.get(16) as u16;
        }
        Ok(SetAngleResponse {
            option,
            angle,
            len: n as u8,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bytes<T: DataType>(m: &T) -> ([u8; MAX_PAYLOAD_LEN], usize) {
        let mut out = [0xAA; MAX_PAYLOAD_LEN];
        let n = m.encode_into(&mut out);
        (out, n)
    }

    #[test]
    fn hand_checked_payloads() {
        // Little-endian fields; pydronecan: StatusMsg1(rpm=12345, pwm=500, status=0xFFFF)
        // is 39 30 f4 01 ff ff.
        let (b, n) = bytes(&StatusMsg1 {
            rpm: 12345,
            pwm: 500,
            status: 0xFFFF,
        });
        assert_eq!(&b[..n], &[0x39, 0x30, 0xF4, 0x01, 0xFF, 0xFF]);
        assert_eq!(
            StatusMsg1::decode(&b[..n]).map(|m| m.counter_clockwise()),
            Ok(true)
        );
        assert!(StatusMsg1::decode(&b[..5]).is_err());
        assert!(StatusMsg1::decode(&b[..7]).is_err());
        // GetMajorConfig response from the vectors: 3C DE 8F 00 00 00 FF.
        let m = GetMajorConfigResponse::decode(&[0x3C, 0xDE, 0x8F, 0, 0, 0, 0xFF]).unwrap();
        assert_eq!(
            m,
            GetMajorConfigResponse {
                direction: false,
                throttle_source: false,
                throttle_channel: 60,
                led_status: 27,
                led_color: 6,
                msg2_rate: 8,
                msg1_rate: 15,
                positioning_angle: 0,
                reserved: [0, 255],
            }
        );
        let (b, n) = bytes(&SetBaudResponse {});
        assert_eq!(n, 0);
        assert_eq!(b, [0; MAX_PAYLOAD_LEN]);
    }

    #[test]
    fn tail_arrays() {
        for p in [&[][..], &[0], &[5, 3], &[1, 2, 3]] {
            let m = GetEscId::new(p).unwrap();
            let (b, n) = bytes(&m);
            assert_eq!(&b[..n], p);
            assert_eq!(GetEscId::decode(&b[..n]), Ok(m));
        }
        assert!(GetEscId::decode(&[1, 2, 3, 4]).is_err());
        let m = SetAngleResponse::new(7, &[0x1234, 0xFFFF]).unwrap();
        let (b, n) = bytes(&m);
        assert_eq!(&b[..n], &[7, 0x34, 0x12, 0xFF, 0xFF]);
        assert_eq!(SetAngleResponse::decode(&b[..n]), Ok(m));
        assert_eq!(
            SetAngleResponse::decode(&b[..3]).map(|m| m.angles().len()),
            Ok(1)
        );
        assert!(SetAngleResponse::decode(&b[..2]).is_err());
        assert!(SetAngleResponse::decode(&[]).is_err());
        assert!(SetAngleResponse::new(0, &[1, 2, 3]).is_none());
    }
}
