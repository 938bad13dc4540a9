//! The built-in demo input: a ten-second run of a virtual ESC, as a logic-analyser CSV in memory.
//!
//! It is made with the codec's encoder and has what a real capture has: idle frames every 364 ms
//! each followed by a device-information frame, a spin-up to 60 % throttle and back with frames
//! every 50 ms, regenerative braking (negative current), a throttle-signal-lost episode, a burst
//! of line noise, a frame with one flipped bit and a skipped packet number.

use std::fmt::Write as _;

use hwfoc::foc::{DataFrame, InfoFrame};
use hwfoc::units::ADC_TABLE;
use hwfoc::{Fault, Status};

/// Seconds per byte at the HW-FOC baud rate, 8N1 (10 bits a byte).
const BYTE_S: f64 = 10.0 / hwfoc::foc::BAUD_RATE as f64;

/// The demo capture as logic-analyser CSV text.
pub fn capture_csv() -> Vec<u8> {
    let mut csv = String::from("Time [s],Value,Parity Error,Framing Error\n");
    let mut put = |t0: f64, bytes: &[u8]| {
        for (i, b) in bytes.iter().enumerate() {
            // Writing to a String cannot fail.
            let _ = writeln!(csv, "{:.9},0x{b:02X},,", t0 + i as f64 * BYTE_S);
        }
    };
    let info = InfoFrame::new("XR_FOC_ESC", "HW577_KZ1_V1.1", "XR-01.0.00", "01040443")
        .map(|i| i.encode())
        .unwrap_or([0; 77]);
    let adc = |celsius: f64| ADC_TABLE[celsius.round().clamp(0.0, 129.0) as usize];

    let mut packet: u16 = 65_500; // wraps during the run
    let (mut rpm, mut mos, mut cap, mut t) = (0.0f64, 24.0f64, 23.0f64, 0.25f64);
    let mut noise: u32 = 0x2545_F491;
    while t < 10.0 {
        let running = (2.0..8.0).contains(&t);
        let throttle = match t {
            _ if !running => 0.0,
            x if x < 4.0 => (x - 2.0) / 2.0 * 0.6,
            x if x < 6.0 => 0.6,
            x => (0.6 - (x - 6.0) / 1.5 * 0.6).max(0.0),
        };
        // RPM follows throttle with a lag; current rises with load and goes negative on braking.
        let target = throttle * 9000.0;
        let braking = target < rpm - 300.0;
        rpm += (target - rpm) * 0.15;
        let amps = if braking {
            -(rpm - target) / 900.0
        } else {
            throttle * throttle * 40.0 + 0.3 * f64::from(u8::from(running))
        };
        let volts = 25.2 - amps * 0.03;
        mos += (amps.abs() * 1.2 + 24.0 - mos) * 0.02;
        cap += (amps.abs() * 0.6 + 23.0 - cap) * 0.015;
        let mut status = Status::OK;
        if (5.0..5.3).contains(&t) {
            status = status.with(Fault::ThrottleSignalLost);
        }
        let frame = DataFrame {
            packet,
            throttle_in_raw: (throttle * 1024.0).round() as u16,
            throttle_out_raw: (throttle * 1024.0 * 0.98).round() as u16,
            erpm_raw: (rpm * 7.0 / 10.0).round() as u16,
            voltage_raw: (volts * 10.0).round() as u16,
            current_raw: (amps * 64.0).round() as i16,
            phase_current_raw: (amps * 64.0 * 1.4).round() as i16,
            mos_adc: adc(mos),
            cap_adc: adc(cap),
            status,
        };
        let mut bytes = frame.encode();
        if (6.5..6.55).contains(&t) {
            bytes[9] ^= 0x10; // one flipped bit: only the checksum catches it
        }
        put(t, &bytes);
        if (3.0..3.05).contains(&t) {
            // A burst of line noise, with sync bytes and a fake header in it.
            let mut junk = [0u8; 40];
            for b in &mut junk {
                noise ^= noise << 13;
                noise ^= noise >> 17;
                noise ^= noise << 5;
                *b = noise as u8;
            }
            junk[5] = 0x9B;
            junk[17] = 0x9B;
            junk[18] = 0x16;
            put(t + 0.015, &junk);
        }
        packet = packet.wrapping_add(if (7.0..7.05).contains(&t) { 2 } else { 1 });
        if running {
            t += 0.050;
        } else {
            put(t + 0.040, &info);
            t += 0.364;
        }
    }
    csv.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::telemetry::AnyFrame;
    use hwfoc::{Quantity, Telemetry};
    use hwfoc_io::Input;
    use hwfoc_io::Stream;

    #[test]
    fn demo_decodes_as_designed() {
        let mut input = Input::from_memory("demo", capture_csv()).unwrap();
        let mut stream = Stream::new();
        let (mut data, mut info, mut faulted, mut braking) = (0, 0, 0, 0);
        let mut on_frame = |t: Option<f64>, _channel: Option<u8>, frame: &AnyFrame| {
            assert!(t.is_some());
            match frame {
                AnyFrame::Data(f) => {
                    data += 1;
                    let status = f.status().unwrap();
                    faulted += usize::from(status.contains(Fault::ThrottleSignalLost));
                    braking += usize::from(f.raw(Quantity::Current).unwrap() < 0);
                }
                AnyFrame::Info(i) => {
                    assert_eq!(i.product(), "XR_FOC_ESC");
                    info += 1;
                }
            }
        };
        while let Some(batch) = input.next_batch().unwrap() {
            stream.feed(batch, &mut on_frame);
        }
        stream.finish(&mut on_frame);
        let s = stream.stats();
        assert!(data > 100, "{data} data frames");
        assert!(info >= 10, "{info} info frames");
        assert_eq!(faulted, 6);
        assert!(braking > 3, "{braking} braking frames");
        assert_eq!(s.checksum_failures(), 2); // the flipped bit and the fake header
        assert_eq!(s.lost_packets(), 2); // the skipped number and the corrupted frame
    }
}
