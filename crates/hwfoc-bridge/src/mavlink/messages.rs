//! What each MAVLink message carries: hwfoc's records in the units of the message definitions.
//!
//! Pure functions from the ESCs of one group of four (the [`Slot`]s) to the messages of the
//! ArduPilot dialect (`ESC_TELEMETRY_x_TO_y`) and of the common set (`ESC_INFO`, `ESC_STATUS`).
//! An ESC that is offline (never heard, or silent for [`crate::SILENT_AFTER`]) is a `None` slot:
//! zeros, except `ESC_INFO.temperature` (`INT16_MAX`, "not supplied") and `error_count` (a count
//! since the bridge started, kept).

use ::mavlink::dialects::ardupilotmega::{
    ESC_INFO_DATA, ESC_STATUS_DATA, ESC_TELEMETRY_1_TO_4_DATA, ESC_TELEMETRY_5_TO_8_DATA,
    ESC_TELEMETRY_9_TO_12_DATA, ESC_TELEMETRY_13_TO_16_DATA, ESC_TELEMETRY_17_TO_20_DATA,
    ESC_TELEMETRY_21_TO_24_DATA, ESC_TELEMETRY_25_TO_28_DATA, ESC_TELEMETRY_29_TO_32_DATA,
    EscConnectionType, EscFailureFlags, MavMessage,
};
use hwfoc::{Fault, Status};
use hwfoc_io::Record;

/// ESCs per message: every ESC message carries a group of four.
pub const GROUP: usize = 4;

/// Groups that have an `ESC_TELEMETRY_x_TO_y` message in the ArduPilot dialect (ESCs 1 to 32).
pub const TELEMETRY_GROUPS: usize = 8;

/// Groups that `ESC_INFO` and `ESC_STATUS` can address (`index` is at most 60: ESCs 1 to 64).
/// ESCs above 64 are not sent.
pub const STATUS_GROUPS: usize = 16;

/// One online ESC of a group, as the messages need it.
#[derive(Debug, Clone, Copy)]
pub struct Slot {
    /// The ESC's latest frame in physical units.
    pub record: Record,
    /// Frames received from the ESC since the bridge started.
    pub frames: u64,
    /// Charge consumed, mAh (`hwfoc_io::energy::Energy::charge_mah`).
    pub consumed_mah: f64,
}

/// The `ESC_FAILURE_FLAGS` bits (common.xml) for a status word:
///
/// | hwfoc fault | `ESC_FAILURE_FLAGS` |
/// |---|---|
/// | `over_current` | `ESC_FAILURE_OVER_CURRENT` |
/// | `input_voltage_high` | `ESC_FAILURE_OVER_VOLTAGE` |
/// | `mos_overheat`, `cap_overheat` | `ESC_FAILURE_OVER_TEMPERATURE` |
/// | `motor_blocked` | `ESC_FAILURE_MOTOR_STUCK` |
/// | `throttle_not_zeroed` | `ESC_FAILURE_INCONSISTENT_CMD` (a command out of bounds: the throttle was not at zero when the ESC started) |
/// | `input_voltage_low`, `throttle_signal_lost`, `upper_bridge_open`, `mos_short`, `lower_bridge_open`, `opamp_phase_a/b/c` | `ESC_FAILURE_GENERIC` (the enum has no under-voltage, signal-loss or hardware flag) |
/// | `reserved_3`, `reserved_15` | nothing (bits the vendor does not assign) |
///
/// `ESC_FAILURE_OVER_RPM` is never set: no Hobbywing fault means it.
pub fn failure_flags(status: Status) -> u16 {
    let mut flags = EscFailureFlags::empty();
    for fault in status {
        flags |= match fault {
            Fault::OverCurrent => EscFailureFlags::ESC_FAILURE_OVER_CURRENT,
            Fault::InputVoltageHigh => EscFailureFlags::ESC_FAILURE_OVER_VOLTAGE,
            Fault::MosOverheat | Fault::CapOverheat => {
                EscFailureFlags::ESC_FAILURE_OVER_TEMPERATURE
            }
            Fault::MotorBlocked => EscFailureFlags::ESC_FAILURE_MOTOR_STUCK,
            Fault::ThrottleNotZeroed => EscFailureFlags::ESC_FAILURE_INCONSISTENT_CMD,
            Fault::InputVoltageLow
            | Fault::ThrottleSignalLost
            | Fault::UpperBridgeOpen
            | Fault::MosShort
            | Fault::LowerBridgeOpen
            | Fault::OpampPhaseC
            | Fault::OpampPhaseB
            | Fault::OpampPhaseA => EscFailureFlags::ESC_FAILURE_GENERIC,
            Fault::Reserved3 | Fault::Reserved15 => EscFailureFlags::empty(),
        };
    }
    flags.bits()
}

/// The ESC's temperature: the hotter of its MOSFET and capacitor temperatures, where known.
pub fn temperature_c(record: &Record) -> Option<f32> {
    match (record.mos_temp_c, record.cap_temp_c) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
}

/// `value` rounded to the nearest integer and held within `0..=max`.
fn round_to(value: f64, max: f64) -> f64 {
    value.round().clamp(0.0, max)
}

/// The four columns of an `ESC_TELEMETRY_x_TO_y` message: temperature (degC), voltage (cV),
/// current (cA), totalcurrent (mAh consumed), rpm (motor RPM under the bridge's settings), count
/// (frames received, wrapping at 65536). Negative values (regenerative current, charge given
/// back) are sent as 0: the fields are unsigned.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TelemetryColumns {
    /// degC.
    pub temperature: [u8; 4],
    /// cV.
    pub voltage: [u16; 4],
    /// cA.
    pub current: [u16; 4],
    /// mAh.
    pub totalcurrent: [u16; 4],
    /// rev/min.
    pub rpm: [u16; 4],
    /// Frames received.
    pub count: [u16; 4],
}

impl TelemetryColumns {
    /// The columns of the slots of a group.
    pub fn new(slots: &[Option<Slot>; GROUP]) -> TelemetryColumns {
        let mut c = TelemetryColumns::default();
        for (i, slot) in slots.iter().enumerate() {
            let Some(s) = slot else { continue };
            let r = &s.record;
            let u16max = f64::from(u16::MAX);
            c.temperature[i] = temperature_c(r).map_or(0, |t| round_to(f64::from(t), 255.0) as u8);
            // A quantity the ESC's protocol does not carry is 0: the fields have no "unknown".
            c.voltage[i] = r
                .voltage_v
                .map_or(0, |v| round_to(f64::from(v) * 100.0, u16max) as u16);
            c.current[i] = r
                .current_a
                .map_or(0, |a| round_to(f64::from(a) * 100.0, u16max) as u16);
            c.totalcurrent[i] = round_to(s.consumed_mah, u16max) as u16;
            c.rpm[i] = r
                .rpm
                .map_or(0, |rpm| round_to(f64::from(rpm), u16max) as u16);
            c.count[i] = s.frames as u16;
        }
        c
    }
}

/// The `ESC_TELEMETRY_x_TO_y` message of group `group` (ESCs `4 * group + 1` to
/// `4 * group + 4`), or `None` above ESC 32 (the dialect has no message for them).
pub fn esc_telemetry(group: usize, slots: &[Option<Slot>; GROUP]) -> Option<MavMessage> {
    let c = TelemetryColumns::new(slots);
    macro_rules! telemetry {
        ($variant:ident, $data:ident) => {
            MavMessage::$variant($data {
                temperature: c.temperature,
                voltage: c.voltage,
                current: c.current,
                totalcurrent: c.totalcurrent,
                rpm: c.rpm,
                count: c.count,
            })
        };
    }
    Some(match group {
        0 => telemetry!(ESC_TELEMETRY_1_TO_4, ESC_TELEMETRY_1_TO_4_DATA),
        1 => telemetry!(ESC_TELEMETRY_5_TO_8, ESC_TELEMETRY_5_TO_8_DATA),
        2 => telemetry!(ESC_TELEMETRY_9_TO_12, ESC_TELEMETRY_9_TO_12_DATA),
        3 => telemetry!(ESC_TELEMETRY_13_TO_16, ESC_TELEMETRY_13_TO_16_DATA),
        4 => telemetry!(ESC_TELEMETRY_17_TO_20, ESC_TELEMETRY_17_TO_20_DATA),
        5 => telemetry!(ESC_TELEMETRY_21_TO_24, ESC_TELEMETRY_21_TO_24_DATA),
        6 => telemetry!(ESC_TELEMETRY_25_TO_28, ESC_TELEMETRY_25_TO_28_DATA),
        7 => telemetry!(ESC_TELEMETRY_29_TO_32, ESC_TELEMETRY_29_TO_32_DATA),
        _ => return None,
    })
}

/// `ESC_STATUS` of group `group`: motor RPM (signed, rounded), voltage (V) and current (A,
/// negative while braking regeneratively) as the records have them.
pub fn esc_status(group: usize, time_usec: u64, slots: &[Option<Slot>; GROUP]) -> MavMessage {
    let mut data = ESC_STATUS_DATA {
        index: (group * GROUP) as u8,
        time_usec,
        ..ESC_STATUS_DATA::default()
    };
    for (i, slot) in slots.iter().enumerate() {
        let Some(s) = slot else { continue };
        // A quantity the ESC's protocol does not carry: rpm 0, voltage and current NaN.
        data.rpm[i] = s.record.rpm.map_or(0, |rpm| {
            f64::from(rpm)
                .round()
                .clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
        });
        data.voltage[i] = s.record.voltage_v.unwrap_or(f32::NAN);
        data.current[i] = s.record.current_a.unwrap_or(f32::NAN);
    }
    MavMessage::ESC_STATUS(data)
}

/// The `ESC_INFO.info` bitmask and `failure_flags` of a group: which ESCs are online (bit `i`
/// for the group's ESC `i`), and their failures.
pub fn info_state(slots: &[Option<Slot>; GROUP]) -> (u8, [u16; 4]) {
    let mut info = 0;
    let mut flags = [0; 4];
    for (i, slot) in slots.iter().enumerate() {
        if let Some(s) = slot {
            info |= 1 << i;
            flags[i] = s.record.status.map_or(0, failure_flags);
        }
    }
    (info, flags)
}

/// What `ESC_INFO` says besides the slots.
#[derive(Debug, Clone, Copy)]
pub struct InfoContext {
    /// Unix time, microseconds.
    pub time_usec: u64,
    /// ESCs in all: the highest ESC number heard (1-based).
    pub count: u8,
    /// Frames received from the group's ESCs since the bridge started (wrapping at 65536).
    pub counter: u16,
    /// Fault onsets per ESC of the group since the bridge started (kept while it is offline).
    pub error_count: [u32; 4],
}

/// `ESC_INFO` of group `group`: connection type serial, the online bitmask, failure flags,
/// error counts, temperature (cdegC; `INT16_MAX` when offline or unknown).
pub fn esc_info(group: usize, context: &InfoContext, slots: &[Option<Slot>; GROUP]) -> MavMessage {
    let (info, failure_flags) = info_state(slots);
    let mut temperature = [i16::MAX; 4];
    for (i, slot) in slots.iter().enumerate() {
        if let Some(t) = slot.as_ref().and_then(|s| temperature_c(&s.record)) {
            temperature[i] = (f64::from(t) * 100.0)
                .round()
                .clamp(f64::from(i16::MIN), f64::from(i16::MAX - 1))
                as i16;
        }
    }
    MavMessage::ESC_INFO(ESC_INFO_DATA {
        index: (group * GROUP) as u8,
        time_usec: context.time_usec,
        counter: context.counter,
        count: context.count,
        connection_type: EscConnectionType::ESC_CONNECTION_TYPE_SERIAL,
        info,
        failure_flags,
        error_count: context.error_count,
        temperature,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Hobbywing CAN ESC before its StatusMsg2 and StatusMsg3 (no voltage, current or
    /// temperature): each field goes out as its message's "not available" where the definition
    /// has one (`ESC_INFO.temperature` `INT16_MAX`; NaN for `ESC_STATUS`'s floats), else 0.
    #[test]
    fn quantities_not_carried_go_out_as_not_available_where_defined() {
        use hwfoc::dronecan::HwCanEsc;
        let data = hwfoc::telemetry::Data::from(HwCanEsc {
            node: 3,
            throttle_channel: Some(1),
            transfer_id: 0,
            rpm: 1200,
            pwm: 300,
            status: 0,
            power: None,
            msg2_age_ms: None,
            temperatures: None,
            msg3_age_ms: None,
        });
        let record = Record::new(None, 0, &data, &hwfoc::Settings::DEFAULT);
        assert_eq!((record.voltage_v, record.mos_temp_c), (None, None));
        let slot = Slot {
            record,
            frames: 1,
            consumed_mah: 0.0,
        };
        let slots = [Some(slot), None, None, None];
        let MavMessage::ESC_STATUS(status) = esc_status(0, 1, &slots) else {
            unreachable!()
        };
        assert!(status.voltage[0].is_nan() && status.current[0].is_nan());
        assert_eq!(status.rpm[0], 1200);
        let context = InfoContext {
            time_usec: 1,
            count: 1,
            counter: 1,
            error_count: [0; 4],
        };
        let MavMessage::ESC_INFO(info) = esc_info(0, &context, &slots) else {
            unreachable!()
        };
        assert_eq!(info.temperature[0], i16::MAX);
        let columns = TelemetryColumns::new(&slots);
        assert_eq!(
            (
                columns.temperature[0],
                columns.voltage[0],
                columns.current[0]
            ),
            (0, 0, 0)
        );
        assert_eq!(columns.rpm[0], 1200);
    }

    #[test]
    fn fault_bits_map_to_failure_flags() {
        let flag = |f: Fault| failure_flags(Status::OK.with(f));
        assert_eq!(flag(Fault::OverCurrent), 1);
        assert_eq!(flag(Fault::InputVoltageHigh), 2);
        assert_eq!(flag(Fault::MosOverheat), 4);
        assert_eq!(flag(Fault::CapOverheat), 4);
        assert_eq!(flag(Fault::ThrottleNotZeroed), 16);
        assert_eq!(flag(Fault::MotorBlocked), 32);
        assert_eq!(flag(Fault::InputVoltageLow), 64);
        assert_eq!(flag(Fault::MosShort), 64);
        assert_eq!(flag(Fault::Reserved3), 0);
        assert_eq!(failure_flags(Status(0xFFFF)), 1 | 2 | 4 | 16 | 32 | 64);
        assert_eq!(failure_flags(Status::OK), 0);
    }
}
