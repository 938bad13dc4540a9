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
//! The HW-FOC entry points are behind the default feature `esc`, so that
//! `--no-default-features --features datalink` measures the DataLink decoder alone.
//!
//! The only `unsafe` is the `no_mangle` attribute; the decoder state is the caller's
//! (`&mut Decoder`, opaque to C), so there is no mutable static.

#![no_std]

use hwfoc::foc::Decoder;

/// `size_of::<Decoder>()` on the target; the build fails if it changes (the script reports it).
pub const DECODER_STATE_BYTES: usize = 120;
const _: () = assert!(core::mem::size_of::<Decoder>() == DECODER_STATE_BYTES);

/// `size_of::<hwfoc::datalink::Decoder>()` on the target, checked as [`DECODER_STATE_BYTES`] is.
pub const DATALINK_DECODER_STATE_BYTES: usize = 380;
const _: () =
    assert!(core::mem::size_of::<hwfoc::datalink::Decoder>() == DATALINK_DECODER_STATE_BYTES);

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
    use hwfoc::foc::{Decoder, Frame};

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
            if let Frame::Data(f) = d.frame {
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

#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    loop {}
}
