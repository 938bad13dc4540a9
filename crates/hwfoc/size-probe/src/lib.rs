//! What firmware would link of `hwfoc`: `extern "C"` entry points around the streaming decoder,
//! built as an LTO'd static library so that only the code they reach is left.
//! `scripts/code-size.sh` builds it for `thumbv7em-none-eabihf` and reports the sizes.
//!
//! - `hwfoc_probe_push`: one byte into a [`Decoder`], a few raw fields of the last data frame out.
//! - `hwfoc_probe_push_units` (feature `units`): the same, then physical values (voltage,
//!   currents and RPM under the caller's settings, temperatures from the ADC table).
//! - `hwfoc_probe_datalink_push` (feature `datalink`): one byte into a
//!   [`hwfoc::datalink::Decoder`], the frame counter and a few raw fields of each ESC of the last
//!   DataLink frame out.
//!
//! - `hwfoc_probe_v3_push` (feature `v3`), `hwfoc_probe_v4_push` (`v4`), `hwfoc_probe_hw5_push`
//!   (`hw5`): one byte into [`hwfoc::v3::Decoder`], [`hwfoc::v4::Decoder`] or
//!   [`hwfoc::hw5::Decoder`], a few fields of the last frame out.
//! - `hwfoc_probe_dronecan_push` (feature `dronecan`): the DroneCAN receive path, one CAN frame
//!   into a [`hwfoc::dronecan::Receiver`] (reassembly, CRC, decoding of every known type,
//!   statistics), the source node, kind and a few fields of a completed transfer out.
//!
//! The HW-FOC entry points are behind the default feature `esc`, so that
//! `--no-default-features --features datalink` (or `v3`, `v4`, `hw5`, `dronecan`) measures that
//! decoder alone.
//!
//! The only `unsafe` is the `no_mangle` attribute; the decoder state is the caller's
//! (`&mut Decoder`, opaque to C), so there is no mutable static.

#![no_std]

use hwfoc::foc::Decoder;

/// `size_of::<Decoder>()` on the target; the build fails if it changes (the script reports it).
pub const DECODER_STATE_BYTES: usize = 124;
const _: () = assert!(core::mem::size_of::<Decoder>() == DECODER_STATE_BYTES);

/// `size_of::<hwfoc::datalink::Decoder>()` on the target, checked as [`DECODER_STATE_BYTES`] is.
pub const DATALINK_DECODER_STATE_BYTES: usize = 416;
const _: () =
    assert!(core::mem::size_of::<hwfoc::datalink::Decoder>() == DATALINK_DECODER_STATE_BYTES);

/// `size_of::<hwfoc::v3::Decoder>()` on the target, checked as [`DECODER_STATE_BYTES`] is.
pub const V3_DECODER_STATE_BYTES: usize = 104;
const _: () = assert!(core::mem::size_of::<hwfoc::v3::Decoder>() == V3_DECODER_STATE_BYTES);

/// `size_of::<hwfoc::v4::Decoder>()` on the target, checked as [`DECODER_STATE_BYTES`] is.
pub const V4_DECODER_STATE_BYTES: usize = 184;
const _: () = assert!(core::mem::size_of::<hwfoc::v4::Decoder>() == V4_DECODER_STATE_BYTES);

/// `size_of::<hwfoc::hw5::Decoder>()` on the target, checked as [`DECODER_STATE_BYTES`] is.
pub const HW5_DECODER_STATE_BYTES: usize = 168;
const _: () = assert!(core::mem::size_of::<hwfoc::hw5::Decoder>() == HW5_DECODER_STATE_BYTES);

/// `size_of::<hwfoc::dronecan::Receiver>()` (128 reassembly slots, one per node id, and statistics of every node id)
/// on the target, checked as [`DECODER_STATE_BYTES`] is.
pub const DRONECAN_RECEIVER_STATE_BYTES: usize = 33332;
const _: () =
    assert!(core::mem::size_of::<hwfoc::dronecan::Receiver>() == DRONECAN_RECEIVER_STATE_BYTES);

/// Raw fields of a data frame, as firmware might copy them out.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct ProbeFrame {
    /// Stream offset of the frame's first byte.
    pub offset: u64,
    /// Packet number.
    pub packet: u16,
    /// Input voltage, 0.1 V units.
    pub voltage_raw: u16,
    /// Input current, raw.
    pub current_raw: i16,
    /// Phase current, raw.
    pub phase_current_raw: i16,
    /// Electrical RPM / 10.
    pub erpm_raw: u16,
    /// Status word (fault bits).
    pub status: u16,
    /// MOSFET temperature ADC code.
    pub mos_adc: u8,
    /// Capacitor temperature ADC code.
    pub cap_adc: u8,
}

#[cfg(feature = "esc")]
pub use esc::*;

#[cfg(feature = "esc")]
mod esc {
    use hwfoc::foc::{Decoder, FocFrame};

    use crate::ProbeFrame;

    /// Pushes one byte into `state`; returns true and fills `out` when the byte completes at least
    /// one data frame (the last one if it completes several). Info frames are decoded but not copied.
    #[unsafe(no_mangle)]
    #[inline(never)] // called from `hwfoc_probe_push_units` too: keep one copy of the decoder
    pub extern "C" fn hwfoc_probe_push(
        state: &mut Decoder,
        byte: u8,
        out: &mut ProbeFrame,
    ) -> bool {
        let mut got = false;
        state.push(byte, |d| {
            if let FocFrame::Data(f) = d.frame {
                *out = ProbeFrame {
                    offset: d.offset,
                    packet: f.packet,
                    voltage_raw: f.voltage_raw,
                    current_raw: f.current_raw,
                    phase_current_raw: f.phase_current_raw,
                    erpm_raw: f.erpm_raw,
                    status: f.status.0,
                    mos_adc: f.mos_adc,
                    cap_adc: f.cap_adc,
                };
                got = true;
            }
        });
        got
    }
}

#[cfg(feature = "units")]
pub use units::*;

#[cfg(feature = "units")]
mod units {
    use hwfoc::foc::{DataFrame, Decoder};
    use hwfoc::{Settings, Status};

    use crate::{ProbeFrame, hwfoc_probe_push};

    /// Conversion settings from the caller.
    #[repr(C)]
    #[derive(Debug, Clone, Copy)]
    pub struct ProbeSettings {
        /// Raw current units per ampere.
        pub current_scale: f32,
        /// Gear ratio.
        pub gear_ratio: f32,
        /// Motor pole pairs.
        pub pole_pairs: u16,
    }

    /// Physical values of a data frame; temperatures are NaN when out of the table's range.
    #[repr(C)]
    #[derive(Debug, Clone, Copy, Default)]
    pub struct ProbeValues {
        /// Raw fields.
        pub raw: ProbeFrame,
        /// Input voltage, V.
        pub voltage_v: f32,
        /// Input current, A.
        pub current_a: f32,
        /// Phase current, A.
        pub phase_current_a: f32,
        /// Mechanical RPM.
        pub rpm: f32,
        /// MOSFET temperature, degC.
        pub mos_c: f32,
        /// Capacitor temperature, degC.
        pub cap_c: f32,
    }

    /// [`hwfoc_probe_push`], then the conversions to physical units.
    #[unsafe(no_mangle)]
    pub extern "C" fn hwfoc_probe_push_units(
        state: &mut Decoder,
        byte: u8,
        settings: &ProbeSettings,
        out: &mut ProbeValues,
    ) -> bool {
        if !hwfoc_probe_push(state, byte, &mut out.raw) {
            return false;
        }
        let r = &out.raw;
        let frame = DataFrame {
            packet: r.packet,
            voltage_raw: r.voltage_raw,
            current_raw: r.current_raw,
            phase_current_raw: r.phase_current_raw,
            erpm_raw: r.erpm_raw,
            mos_adc: r.mos_adc,
            cap_adc: r.cap_adc,
            status: Status(r.status),
            ..DataFrame::default()
        };
        let settings = Settings {
            current_scale: settings.current_scale,
            pole_pairs: settings.pole_pairs,
            gear_ratio: settings.gear_ratio,
            ..Settings::DEFAULT
        };
        out.voltage_v = frame.voltage_v();
        out.current_a = frame.current_a(&settings);
        out.phase_current_a = frame.phase_current_a(&settings);
        out.rpm = frame.rpm(&settings);
        out.mos_c = frame.mos_temp().celsius().unwrap_or(f32::NAN);
        out.cap_c = frame.cap_temp().celsius().unwrap_or(f32::NAN);
        true
    }
}

#[cfg(feature = "datalink")]
pub use datalink::*;

#[cfg(feature = "datalink")]
mod datalink {
    use hwfoc::datalink;
    use hwfoc::datalink::CHANNELS;

    /// Raw fields of one ESC of a DataLink frame.
    #[repr(C)]
    #[derive(Debug, Clone, Copy, Default)]
    pub struct ProbeEsc {
        /// Packet number.
        pub packet: u16,
        /// Input voltage, 0.1 V units.
        pub voltage_raw: u16,
        /// Input current, raw.
        pub current_raw: i16,
        /// Electrical RPM / 10.
        pub erpm_raw: u16,
        /// Status word (fault bits).
        pub status: u16,
        /// 1 when the slot holds an ESC, else 0.
        pub present: u8,
    }

    /// A DataLink frame as firmware might copy it out.
    #[repr(C)]
    #[derive(Debug, Clone, Copy, Default)]
    pub struct ProbeDatalink {
        /// Stream offset of the frame's first byte.
        pub offset: u64,
        /// The hub's frame counter.
        pub counter: u16,
        /// The ESCs by channel.
        pub escs: [ProbeEsc; CHANNELS],
    }

    /// Pushes one byte into `state`; returns true and fills `out` when the byte completes a
    /// DataLink frame.
    #[unsafe(no_mangle)]
    pub extern "C" fn hwfoc_probe_datalink_push(
        state: &mut datalink::Decoder,
        byte: u8,
        out: &mut ProbeDatalink,
    ) -> bool {
        let mut got = false;
        state.push(byte, |d| {
            out.offset = d.offset;
            out.counter = d.frame.counter;
            for (o, slot) in out.escs.iter_mut().zip(&d.frame.slots) {
                *o = match slot {
                    Some(e) => ProbeEsc {
                        packet: e.packet,
                        voltage_raw: e.voltage_raw,
                        current_raw: e.current_raw,
                        erpm_raw: e.erpm_raw,
                        status: e.status.0,
                        present: 1,
                    },
                    None => ProbeEsc::default(),
                };
            }
            got = true;
        });
        got
    }
}

#[cfg(feature = "v3")]
pub use v3::*;

#[cfg(feature = "v3")]
mod v3 {
    use hwfoc::v3;

    /// A V3 frame as firmware might copy it out.
    #[repr(C)]
    #[derive(Debug, Clone, Copy, Default)]
    pub struct ProbeV3 {
        /// Stream offset of the frame's first byte.
        pub offset: u64,
        /// Packet counter (24 bits).
        pub counter: u32,
        /// Input throttle, 0..=255.
        pub throttle_in_raw: u16,
        /// Output PWM, 0..=255.
        pub pwm_out_raw: u16,
        /// Microseconds per electrical revolution.
        pub period_us: u16,
    }

    /// Pushes one byte into `state`; returns true and fills `out` when the byte completes a V3
    /// frame.
    #[unsafe(no_mangle)]
    pub extern "C" fn hwfoc_probe_v3_push(
        state: &mut v3::Decoder,
        byte: u8,
        out: &mut ProbeV3,
    ) -> bool {
        let mut got = false;
        state.push(byte, |d| {
            *out = ProbeV3 {
                offset: d.offset,
                counter: d.frame.counter,
                throttle_in_raw: d.frame.throttle_in_raw,
                pwm_out_raw: d.frame.pwm_out_raw,
                period_us: d.frame.period_us,
            };
            got = true;
        });
        got
    }
}

#[cfg(feature = "v4")]
pub use v4::*;

#[cfg(feature = "v4")]
mod v4 {
    use hwfoc::v4;

    /// A V4 data frame as firmware might copy it out (raw fields).
    #[repr(C)]
    #[derive(Debug, Clone, Copy, Default)]
    pub struct ProbeV4 {
        /// Stream offset of the frame's first byte.
        pub offset: u64,
        /// Packet counter (24 bits).
        pub counter: u32,
        /// Electrical RPM (24 bits).
        pub erpm: u32,
        /// Input throttle, 0..=full scale.
        pub throttle_in_raw: u16,
        /// Output PWM, 0..=full scale.
        pub throttle_out_raw: u16,
        /// Voltage ADC value.
        pub voltage_adc: u16,
        /// Current ADC value.
        pub current_adc: u16,
        /// MOSFET temperature ADC value.
        pub temp_adc: u16,
        /// Full scale of throttle and PWM in use (the adopted info frame's, else 1000).
        pub full_scale: u16,
    }

    /// Pushes one byte into `state`; returns true and fills `out` when the byte completes a V4
    /// data frame (info frames are decoded and adopted, not copied).
    #[unsafe(no_mangle)]
    pub extern "C" fn hwfoc_probe_v4_push(
        state: &mut v4::Decoder,
        byte: u8,
        out: &mut ProbeV4,
    ) -> bool {
        let mut got = false;
        state.push(byte, |d| {
            if let v4::V4Frame::Data(data) = d.frame {
                let f = data.frame;
                *out = ProbeV4 {
                    offset: d.offset,
                    counter: f.counter,
                    erpm: f.erpm,
                    throttle_in_raw: f.throttle_in_raw,
                    throttle_out_raw: f.throttle_out_raw,
                    voltage_adc: f.voltage_adc,
                    current_adc: f.current_adc,
                    temp_adc: f.temp_adc,
                    full_scale: data.full_scale(),
                };
                got = true;
            }
        });
        got
    }
}

#[cfg(feature = "hw5")]
pub use hw5::*;

#[cfg(feature = "hw5")]
mod hw5 {
    use hwfoc::hw5;

    /// An HW5 telemetry frame as firmware might copy it out (raw fields).
    #[repr(C)]
    #[derive(Debug, Clone, Copy, Default)]
    pub struct ProbeHw5 {
        /// Stream offset of the frame's first byte.
        pub offset: u64,
        /// eRPM / 10.
        pub erpm_raw: u16,
        /// Input voltage, 0.1 V.
        pub voltage_raw: u16,
        /// Input current, 0.1 A.
        pub current_raw: u16,
        /// Throttle, %.
        pub throttle: u8,
        /// Fault flags.
        pub fault: u8,
        /// ESC temperature, degC.
        pub esc_temp: u8,
        /// Motor temperature, degC.
        pub motor_temp: u8,
    }

    /// Pushes one byte into `state`; returns true and fills `out` when the byte completes an
    /// HW5 telemetry frame (frames of the other kinds are verified and counted, not copied).
    #[unsafe(no_mangle)]
    pub extern "C" fn hwfoc_probe_hw5_push(
        state: &mut hw5::Decoder,
        byte: u8,
        out: &mut ProbeHw5,
    ) -> bool {
        let mut got = false;
        state.push(byte, |d| {
            let f = d.frame;
            *out = ProbeHw5 {
                offset: d.offset,
                erpm_raw: f.erpm_raw,
                voltage_raw: f.voltage_raw,
                current_raw: f.current_raw,
                throttle: f.throttle,
                fault: f.fault.0,
                esc_temp: f.esc_temp,
                motor_temp: f.motor_temp,
            };
            got = true;
        });
        got
    }
}

#[cfg(feature = "dronecan")]
pub use dronecan::*;

#[cfg(feature = "dronecan")]
mod dronecan {
    use hwfoc::dronecan::{CanFrame, Message, Receiver};

    /// A CAN frame as a CAN peripheral delivers it.
    #[repr(C)]
    #[derive(Debug, Clone, Copy, Default)]
    pub struct ProbeCanFrame {
        /// The 29-bit identifier.
        pub id: u32,
        /// Data length, 0..=8.
        pub len: u8,
        /// The data bytes.
        pub data: [u8; 8],
    }

    /// A decoded transfer as firmware might copy it out: who sent it, its kind, and the fields
    /// of the ESC messages (zero for other kinds).
    #[repr(C)]
    #[derive(Debug, Clone, Copy, Default)]
    pub struct ProbeTransfer {
        /// The source node.
        pub source_node: u8,
        /// The transfer id.
        pub transfer_id: u8,
        /// `Kind as u8`.
        pub kind: u8,
        /// StatusMsg1's rpm, or esc.Status's rpm.
        pub rpm: i32,
        /// StatusMsg1's pwm.
        pub pwm: u16,
        /// StatusMsg1's status word.
        pub status: u16,
        /// StatusMsg2's input voltage (0.1 V), or esc.Status's voltage in 0.1 V.
        pub voltage_raw: i16,
        /// StatusMsg2's current (0.1 A), or esc.Status's current in 0.1 A.
        pub current_raw: i16,
        /// StatusMsg2's temperature, or StatusMsg3's MOSFET temperature, degC.
        pub temperature: u8,
    }

    /// Pushes one extended data frame into `state`; returns true and fills `out` when it
    /// completes a transfer of a known type.
    #[unsafe(no_mangle)]
    pub extern "C" fn hwfoc_probe_dronecan_push(
        state: &mut Receiver,
        frame: &ProbeCanFrame,
        out: &mut ProbeTransfer,
    ) -> bool {
        let len = usize::from(frame.len).min(8);
        let Some(frame) = CanFrame::extended(frame.id, &frame.data[..len]) else {
            return false;
        };
        let Some(r) = state.push(&frame) else {
            return false;
        };
        *out = ProbeTransfer {
            source_node: r.header.source_node,
            transfer_id: r.transfer_id,
            kind: r.message.kind() as u8,
            ..ProbeTransfer::default()
        };
        match r.message {
            Message::StatusMsg1(m) => {
                out.rpm = i32::from(m.rpm);
                out.pwm = m.pwm;
                out.status = m.status;
            }
            Message::StatusMsg2(m) => {
                out.voltage_raw = m.input_voltage;
                out.current_raw = m.current;
                out.temperature = m.temperature;
            }
            Message::StatusMsg3(m) => out.temperature = m.mos_t,
            Message::EscStatus(m) => {
                out.rpm = m.rpm;
                out.voltage_raw = (m.voltage * 10.0) as i16;
                out.current_raw = (m.current * 10.0) as i16;
            }
            _ => {}
        }
        true
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    loop {}
}
