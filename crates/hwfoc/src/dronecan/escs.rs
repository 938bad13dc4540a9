//! The ESCs of a DroneCAN bus: which node is which ESC, and one telemetry record per status
//! message carrying the latest values of the slower messages, each with its age.
//!
//! [`Escs::push`] takes every decoded transfer ([`Received`]) with its receive time and keeps,
//! per node:
//!
//! - the throttle channel a `com.hobbywing.esc.GetEscID` answer (`[node, channel]`) gave it;
//! - the latest `StatusMsg2` (voltage, current, ESC temperature) and `StatusMsg3` (MOSFET,
//!   capacitor, motor temperatures) of a Hobbywing ESC, and the latest
//!   `uavcan.equipment.esc.StatusExtended` of a standard DroneCAN ESC, each with its time;
//! - whether its motor turns (the last `StatusMsg1`'s rpm or pwm, or `Status`'s rpm, above 0);
//! - its maintenance counters from the last `com.hobbywing.esc.GetMaintenanceInformation`
//!   answer it sent (total rotation time, time since maintenance: [`Escs::maintenance_min`]),
//!   where the bus's recording holds one (`hwfoc can list`, a DataLink or a GCS asked).
//!
//! Each `StatusMsg1` is a [`HwCanEsc`] record (protocol `hw-can`) and each
//! `uavcan.equipment.esc.Status` a [`DroneCanEsc`] record (protocol `dronecan`), with the slower
//! messages' values as they last came and their ages at the record (milliseconds; `None` where
//! either time is unknown). Records are the codec's [`Data`](crate::telemetry::Data), read
//! through [`Telemetry`] as every protocol's.
//!
//! ```
//! use hwfoc::dronecan::{Escs, GetEscId, Message, Receiver, StatusMsg1, StatusMsg2};
//! use hwfoc::telemetry::{Data, Telemetry};
//! use hwfoc::{Quantity, Settings};
//!
//! let (mut rx, mut escs) = (Receiver::new(), Escs::new());
//! let mut feed = |m: Message, node: u8, t_us: u64| {
//!     let mut out = None;
//!     for f in m.frames(16, node, 0, 0) {
//!         if let Some(got) = rx.push(&f) {
//!             out = escs.push(&got, Some(t_us));
//!         }
//!     }
//!     out
//! };
//! let v = StatusMsg2 { input_voltage: 252, current: 105, temperature: 41 };
//! assert!(feed(Message::from(v), 7, 1_000).is_none());
//! assert!(feed(Message::from(GetEscId::new(&[7, 3]).unwrap()), 7, 2_000).is_none());
//! let m1 = StatusMsg1 { rpm: 4200, pwm: 350, status: StatusMsg1::STATUS_CCW };
//! let Some(Data::HwCan(r)) = feed(Message::from(m1), 7, 21_000) else { panic!() };
//! assert_eq!((r.node, r.throttle_channel, r.bus_place(), r.ccw()), (7, Some(3), 2, true));
//! assert_eq!(r.msg2_age_ms, Some(20));
//! let s = Settings::default();
//! assert_eq!(r.value(Quantity::Voltage, &s), Some(25.2));
//! assert_eq!(r.value(Quantity::ThrottleOut, &s), Some(35.0));
//! assert_eq!(r.value(Quantity::Rpm, &s), Some(4200.0));
//! ```

use super::bits::{f16_from_f32, f32_from_f16};
use super::kind::Message;
use super::receiver::Received;
use super::stats::NODES;
use crate::status::Status;
use crate::telemetry::{Conversion, Reading, Telemetry};
use crate::units::{Linear, Quantity, Settings};

/// Tenths of the unit: Hobbywing's 0.1 V and 0.1 A.
const TENTHS: Linear = Linear::VOLTS;
/// StatusMsg1's `pwm` (0-1000) as output throttle in percent.
const PWM_PCT: Linear = Linear::new(100.0, 1000.0, 1.0);

/// `com.hobbywing.esc.StatusMsg2`'s values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Power {
    /// Input voltage, 0.1 V.
    pub input_voltage: i16,
    /// Input current, 0.1 A.
    pub current: i16,
    /// The ESC's temperature, degC.
    pub temperature: u8,
}

/// `com.hobbywing.esc.StatusMsg3`'s values, degC.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Temperatures {
    /// MOSFETs.
    pub mos: u8,
    /// Capacitors.
    pub cap: u8,
    /// Motor.
    pub motor: u8,
}

/// A Hobbywing CAN ESC's telemetry at one `StatusMsg1` (protocol `hw-can`): its values, and the
/// latest `StatusMsg2` and `StatusMsg3` of the node with their ages.
///
/// Readings ([`Telemetry`]): `rpm` as the ESC sends it (whether mechanical or electrical is not
/// documented: no eRPM, no pole pairs applied), `pwm` (0-1000) as the output throttle in
/// percent, voltage and current in tenths, the MOSFET, capacitor and motor temperatures of
/// `StatusMsg3` (before the node's first `StatusMsg3`, `StatusMsg2`'s ESC temperature as the
/// MOSFETs'); the raw `status` word ([`HwCanEsc::ccw`]: bit 14).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct HwCanEsc {
    /// The sending node.
    pub node: u8,
    /// Its throttle channel (1-based) from a GetEscID answer, if one came.
    pub throttle_channel: Option<u8>,
    /// The StatusMsg1 transfer's id.
    pub transfer_id: u8,
    /// StatusMsg1 `rpm`.
    pub rpm: u16,
    /// StatusMsg1 `pwm`, 0-1000.
    pub pwm: u16,
    /// StatusMsg1 `status`.
    pub status: u16,
    /// The node's latest StatusMsg2.
    pub power: Option<Power>,
    /// Its age at this record, ms.
    pub msg2_age_ms: Option<u32>,
    /// The node's latest StatusMsg3.
    pub temperatures: Option<Temperatures>,
    /// Its age at this record, ms.
    pub msg3_age_ms: Option<u32>,
}

impl HwCanEsc {
    /// Whether the motor turns counter-clockwise (status bit 14).
    pub const fn ccw(&self) -> bool {
        self.status & super::StatusMsg1::STATUS_CCW != 0
    }

    /// Where the ESC is on its bus: its throttle channel - 1 once a GetEscID answer mapped it,
    /// until then its node id ([`HwCanEsc::throttle_channel`] says which).
    pub fn bus_place(&self) -> u8 {
        self.throttle_channel
            .map_or(self.node, |c| c.saturating_sub(1))
    }
}

impl Telemetry for HwCanEsc {
    /// None: a transfer id is the transport's (its gaps are counted per node in
    /// [`NodeStats`](super::NodeStats)).
    fn packet(&self) -> Option<u32> {
        None
    }

    fn status(&self) -> Option<Status> {
        Some(Status(self.status))
    }

    fn reading(&self, quantity: Quantity, _: &Settings) -> Option<Reading> {
        let linear = Reading::linear;
        let power = self.power;
        let temps = self.temperatures;
        Some(match quantity {
            Quantity::ThrottleOut => linear(self.pwm.into(), PWM_PCT),
            Quantity::Rpm => linear(self.rpm.into(), Linear::IDENTITY),
            Quantity::Voltage => linear(power?.input_voltage.into(), TENTHS),
            Quantity::Current => linear(power?.current.into(), TENTHS),
            Quantity::MosTemp => match temps {
                Some(t) => linear(t.mos.into(), Linear::IDENTITY),
                None => linear(power?.temperature.into(), Linear::IDENTITY),
            },
            Quantity::CapTemp => linear(temps?.cap.into(), Linear::IDENTITY),
            Quantity::MotorTemp => linear(temps?.motor.into(), Linear::IDENTITY),
            Quantity::ThrottleIn
            | Quantity::Erpm
            | Quantity::PhaseCurrent
            | Quantity::BecTemp
            | Quantity::BecVoltage
            | Quantity::BecCurrent => return None,
        })
    }
}

/// `uavcan.equipment.esc.StatusExtended`'s values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Extended {
    /// Throttle command received, %.
    pub input_pct: u8,
    /// Output to the motor, %.
    pub output_pct: u8,
    /// Motor temperature, degC.
    pub motor_temperature_deg_c: i16,
    /// Manufacturer-specific flags (19 bits).
    pub status_flags: u32,
}

/// A standard DroneCAN ESC's telemetry at one `uavcan.equipment.esc.Status` (protocol
/// `dronecan`), with the node's latest `StatusExtended` and its age.
///
/// The float16 values are kept as sent (their bits): voltage (V), current (A) and temperature
/// (K, read in degC as the MOSFETs'), NaN (unknown) read as not carried; `rpm` as sent; from
/// StatusExtended the input and output throttles (%) and the motor temperature (degC).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DroneCanEsc {
    /// The sending node.
    pub node: u8,
    /// The Status transfer's id.
    pub transfer_id: u8,
    /// `esc_index` (0-31): the ESC's place on the bus.
    pub esc_index: u8,
    /// `error_count`.
    pub error_count: u32,
    /// `voltage`, float16 bits, V.
    pub voltage_f16: u16,
    /// `current`, float16 bits, A.
    pub current_f16: u16,
    /// `temperature`, float16 bits, K.
    pub temperature_f16: u16,
    /// `rpm`.
    pub rpm: i32,
    /// `power_rating_pct`.
    pub power_rating_pct: u8,
    /// The node's latest StatusExtended.
    pub extended: Option<Extended>,
    /// Its age at this record, ms.
    pub ext_age_ms: Option<u32>,
}

impl DroneCanEsc {
    /// Where the ESC is on its bus: its `esc_index`.
    pub const fn bus_place(&self) -> u8 {
        self.esc_index
    }
}

impl Telemetry for DroneCanEsc {
    /// None, as for [`HwCanEsc`].
    fn packet(&self) -> Option<u32> {
        None
    }

    /// None: the standard Status has no fault word (StatusExtended's flags are the maker's).
    fn status(&self) -> Option<Status> {
        None
    }

    fn reading(&self, quantity: Quantity, _: &Settings) -> Option<Reading> {
        let half = |bits: u16, conversion: Conversion| {
            (!f32_from_f16(bits).is_nan()).then_some(Reading {
                raw: i32::from(bits),
                conversion,
            })
        };
        let ext = self.extended;
        let identity = |raw: i32| Reading::linear(raw, Linear::IDENTITY);
        match quantity {
            Quantity::Voltage => half(self.voltage_f16, Conversion::Half),
            Quantity::Current => half(self.current_f16, Conversion::Half),
            Quantity::MosTemp => half(self.temperature_f16, Conversion::HalfKelvin),
            Quantity::Rpm => Some(identity(self.rpm)),
            Quantity::ThrottleIn => Some(identity(ext?.input_pct.into())),
            Quantity::ThrottleOut => Some(identity(ext?.output_pct.into())),
            Quantity::MotorTemp => Some(identity(ext?.motor_temperature_deg_c.into())),
            Quantity::Erpm
            | Quantity::PhaseCurrent
            | Quantity::CapTemp
            | Quantity::BecTemp
            | Quantity::BecVoltage
            | Quantity::BecCurrent => None,
        }
    }
}

/// What is kept of a node between its status messages.
#[derive(Debug, Clone, Copy)]
struct Node {
    /// Throttle channel from a GetEscID answer (1-based), 0 before one.
    channel: u8,
    power: Option<(Power, Option<u64>)>,
    temperatures: Option<(Temperatures, Option<u64>)>,
    extended: Option<(Extended, Option<u64>)>,
    turning: bool,
    /// The last GetMaintenanceInformation answer's counters, minutes: (total rotation time,
    /// time since maintenance).
    maintenance_min: Option<(u32, u32)>,
}

impl Node {
    const NEW: Node = Node {
        channel: 0,
        power: None,
        temperatures: None,
        extended: None,
        turning: false,
        maintenance_min: None,
    };
}

/// The age in milliseconds at `now` of a value received at `then` (microseconds), saturated;
/// `None` where either is unknown.
fn age_ms(now: Option<u64>, then: Option<u64>) -> Option<u32> {
    let ms = now?.saturating_sub(then?) / 1000;
    Some(u32::try_from(ms).unwrap_or(u32::MAX))
}

/// The ESCs of one DroneCAN bus: which node is which ESC, and a record per status message with
/// its node's slower messages and their ages ([`Escs::push`]). No allocation; about 4 KiB.
#[derive(Debug, Clone)]
pub struct Escs {
    nodes: [Node; NODES],
}

impl Default for Escs {
    fn default() -> Self {
        Escs::new()
    }
}

impl Escs {
    /// Nothing known of any node.
    pub const fn new() -> Escs {
        Escs {
            nodes: [Node::NEW; NODES],
        }
    }

    /// Takes a decoded transfer received at `t_us` (microseconds on any clock; `None` without
    /// times) and returns the telemetry record it makes: a [`HwCanEsc`] for a `StatusMsg1`, a
    /// [`DroneCanEsc`] for a `uavcan.equipment.esc.Status`; `None` for anything else (kept:
    /// the slower messages, GetEscID answers).
    pub fn push(&mut self, rx: &Received, t_us: Option<u64>) -> Option<crate::telemetry::Data> {
        let source = rx.header.source_node;
        let node = self.nodes.get_mut(usize::from(source))?;
        match rx.message {
            Message::StatusMsg1(m) => {
                node.turning = m.rpm > 0 || m.pwm > 0;
                let (power, msg2_age_ms) = split(node.power, t_us);
                let (temperatures, msg3_age_ms) = split(node.temperatures, t_us);
                Some(
                    HwCanEsc {
                        node: source,
                        throttle_channel: (node.channel > 0).then_some(node.channel),
                        transfer_id: rx.transfer_id,
                        rpm: m.rpm,
                        pwm: m.pwm,
                        status: m.status,
                        power,
                        msg2_age_ms,
                        temperatures,
                        msg3_age_ms,
                    }
                    .into(),
                )
            }
            Message::StatusMsg2(m) => {
                let p = Power {
                    input_voltage: m.input_voltage,
                    current: m.current,
                    temperature: m.temperature,
                };
                node.power = Some((p, t_us));
                None
            }
            Message::StatusMsg3(m) => {
                let t = Temperatures {
                    mos: m.mos_t,
                    cap: m.cap_t,
                    motor: m.motor_t,
                };
                node.temperatures = Some((t, t_us));
                None
            }
            Message::GetEscId(m) => {
                // An answer names the node it is about; a request ([0]) is not an answer.
                let (about, channel) = m.as_answer()?;
                if let Some(n) = self.nodes.get_mut(usize::from(about)) {
                    n.channel = channel;
                }
                None
            }
            Message::GetMaintenanceInformationResponse(m) => {
                node.maintenance_min =
                    Some((m.total_rotation_time_min, m.time_since_maintenance_min));
                None
            }
            Message::EscStatusExtended(m) => {
                let e = Extended {
                    input_pct: m.input_pct,
                    output_pct: m.output_pct,
                    motor_temperature_deg_c: m.motor_temperature_deg_c,
                    status_flags: m.status_flags,
                };
                node.extended = Some((e, t_us));
                None
            }
            Message::EscStatus(m) => {
                node.turning = m.rpm != 0;
                let (extended, ext_age_ms) = split(node.extended, t_us);
                Some(
                    DroneCanEsc {
                        node: source,
                        transfer_id: rx.transfer_id,
                        esc_index: m.esc_index,
                        error_count: m.error_count,
                        voltage_f16: f16_from_f32(m.voltage),
                        current_f16: f16_from_f32(m.current),
                        temperature_f16: f16_from_f32(m.temperature),
                        rpm: m.rpm,
                        power_rating_pct: m.power_rating_pct,
                        extended,
                        ext_age_ms,
                    }
                    .into(),
                )
            }
            _ => None,
        }
    }

    /// The throttle channel (1-based) a GetEscID answer gave `node`.
    pub fn throttle_channel(&self, node: u8) -> Option<u8> {
        let c = self.nodes.get(usize::from(node))?.channel;
        (c > 0).then_some(c)
    }

    /// The maintenance counters `node` last answered a GetMaintenanceInformation request with,
    /// minutes: (total rotation time, time since maintenance); `None` before an answer.
    pub fn maintenance_min(&self, node: u8) -> Option<(u32, u32)> {
        self.nodes.get(usize::from(node))?.maintenance_min
    }

    /// Whether any node's last status said its motor turns (rpm or throttle above 0).
    pub fn any_turning(&self) -> bool {
        self.nodes.iter().any(|n| n.turning)
    }

    /// Forgets every node (a new bus, or the same after a break in its recording).
    pub fn reset(&mut self) {
        *self = Escs::new();
    }
}

/// A kept value and its age at `now`.
fn split<T: Copy>(kept: Option<(T, Option<u64>)>, now: Option<u64>) -> (Option<T>, Option<u32>) {
    match kept {
        Some((v, t)) => (Some(v), age_ms(now, t)),
        None => (None, None),
    }
}

#[cfg(test)]
mod tests {
    use super::super::{EscStatus, EscStatusExtended, GetEscId, Receiver, StatusMsg1, StatusMsg3};
    use super::*;
    use crate::telemetry::Data;

    fn feed(
        rx: &mut Receiver,
        escs: &mut Escs,
        m: Message,
        node: u8,
        t: Option<u64>,
    ) -> Option<Data> {
        // A new transfer id each time (a repeated one is a duplicate, not handed on).
        static NEXT: core::sync::atomic::AtomicU8 = core::sync::atomic::AtomicU8::new(0);
        let tid = NEXT.fetch_add(1, core::sync::atomic::Ordering::Relaxed) & 31;
        let mut out = None;
        for f in m.frames(16, node, 0, tid) {
            if let Some(got) = rx.push(&f) {
                out = escs.push(&got, t);
            }
        }
        out
    }

    #[test]
    fn hw_can_records_carry_the_slower_messages_with_their_ages() {
        let (mut rx, mut escs) = (Receiver::new(), Escs::new());
        let m1 = StatusMsg1 {
            rpm: 0,
            pwm: 0,
            status: 0,
        };
        let Some(Data::HwCan(r)) = feed(&mut rx, &mut escs, m1.into(), 5, Some(0)) else {
            panic!()
        };
        assert_eq!(
            (r.power, r.temperatures, r.msg2_age_ms, r.throttle_channel),
            (None, None, None, None)
        );
        assert_eq!(r.bus_place(), 5);
        let s = Settings::default();
        assert_eq!(r.value(Quantity::Voltage, &s), None);
        assert_eq!(r.value(Quantity::ThrottleOut, &s), Some(0.0));
        assert!(!escs.any_turning());
        let m3 = StatusMsg3 {
            mos_t: 50,
            cap_t: 40,
            motor_t: 60,
        };
        feed(&mut rx, &mut escs, m3.into(), 5, Some(1_000_000));
        let m1 = StatusMsg1 {
            rpm: 1,
            pwm: 0,
            status: 0,
        };
        let Some(Data::HwCan(r)) = feed(&mut rx, &mut escs, m1.into(), 5, Some(3_500_000)) else {
            panic!()
        };
        assert_eq!(r.msg3_age_ms, Some(2500));
        assert_eq!(r.value(Quantity::MosTemp, &s), Some(50.0));
        assert_eq!(r.value(Quantity::CapTemp, &s), Some(40.0));
        assert_eq!(r.value(Quantity::MotorTemp, &s), Some(60.0));
        assert!(escs.any_turning());
        // Without times: values, no ages.
        let Some(Data::HwCan(r)) = feed(&mut rx, &mut escs, m1.into(), 5, None) else {
            panic!()
        };
        assert_eq!((r.temperatures.is_some(), r.msg3_age_ms), (true, None));
        // A request for ids maps nothing; an answer maps the node it names.
        feed(
            &mut rx,
            &mut escs,
            GetEscId::new(&[0]).unwrap().into(),
            127,
            None,
        );
        assert_eq!(escs.throttle_channel(0), None);
        feed(
            &mut rx,
            &mut escs,
            GetEscId::new(&[5, 1]).unwrap().into(),
            5,
            None,
        );
        assert_eq!(escs.throttle_channel(5), Some(1));
        escs.reset();
        assert_eq!(escs.throttle_channel(5), None);
    }

    #[test]
    fn a_maintenance_answer_is_kept_for_its_node_and_a_request_is_not_one() {
        use super::super::{GetMaintenanceInformationRequest, GetMaintenanceInformationResponse};
        let (mut rx, mut escs) = (Receiver::new(), Escs::new());
        // A service's half goes from one node to another: `from` to `to`.
        let mut send = |m: Message, from: u8, to: u8| {
            for f in m.frames(24, from, to, 0) {
                if let Some(got) = rx.push(&f) {
                    assert!(escs.push(&got, None).is_none());
                }
            }
        };
        let ask = GetMaintenanceInformationRequest { option: 0 };
        send(ask.into(), 127, 5);
        // The answer of docs/HOBBYWING-CAN.md's example, the widest counters: 18F17DFF,
        // FF FF FF FF 1A FC C2 (uint32, then uint24, little-endian as DSDL packs them).
        let answer = GetMaintenanceInformationResponse {
            total_rotation_time_min: 4_294_967_295,
            time_since_maintenance_min: 12_778_522,
        };
        let m = Message::from(answer);
        let mut frames = m.frames(24, 5, 127, 0);
        let only = frames.next().unwrap();
        assert!(frames.next().is_none());
        assert_eq!(only.data()[..7], [0xFF, 0xFF, 0xFF, 0xFF, 0x1A, 0xFC, 0xC2]);
        send(m, 5, 127);
        assert_eq!(escs.maintenance_min(127), None);
        assert_eq!(escs.maintenance_min(5), Some((4_294_967_295, 12_778_522)));
        assert_eq!(escs.maintenance_min(6), None);
        escs.reset();
        assert_eq!(escs.maintenance_min(5), None);
    }

    #[test]
    fn standard_esc_status_is_read_with_its_extended_status() {
        let (mut rx, mut escs) = (Receiver::new(), Escs::new());
        let ext = EscStatusExtended {
            input_pct: 40,
            output_pct: 38,
            motor_temperature_deg_c: -12,
            motor_angle: 0,
            status_flags: 3,
            esc_index: 2,
        };
        feed(&mut rx, &mut escs, ext.into(), 9, Some(10_000));
        let st = EscStatus {
            error_count: 7,
            voltage: 24.5,
            current: -1.5,
            temperature: 313.15,
            rpm: -3000,
            power_rating_pct: 20,
            esc_index: 2,
        };
        let Some(Data::DroneCan(r)) = feed(&mut rx, &mut escs, st.into(), 9, Some(60_000)) else {
            panic!()
        };
        let s = Settings::default();
        assert_eq!(
            (r.bus_place(), r.ext_age_ms, r.error_count),
            (2, Some(50), 7)
        );
        assert_eq!(r.value(Quantity::Voltage, &s), Some(24.5));
        assert_eq!(r.value(Quantity::Current, &s), Some(-1.5));
        // 313.15 K is 313.25 in float16: 40.1 degC.
        let t = r.value(Quantity::MosTemp, &s).unwrap();
        assert!((t - 40.1).abs() < 0.01, "{t}");
        assert_eq!(r.value(Quantity::Rpm, &s), Some(-3000.0));
        assert_eq!(r.value(Quantity::ThrottleIn, &s), Some(40.0));
        assert_eq!(r.value(Quantity::MotorTemp, &s), Some(-12.0));
        assert!(escs.any_turning());
        // Unknown values (NaN) are not carried.
        let st = EscStatus {
            voltage: f32::NAN,
            ..st
        };
        let Some(Data::DroneCan(r)) = feed(&mut rx, &mut escs, st.into(), 9, None) else {
            panic!()
        };
        assert_eq!(r.value(Quantity::Voltage, &s), None);
    }
}
