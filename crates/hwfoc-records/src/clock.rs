//! Receive times: a chunk's bytes timed from its receive time, and the steps between frames
//! (the clock that stamps what is received, reading the system's clocks, is `hwfoc-io`'s).

/// Receive time in Unix seconds of byte `i` of a chunk whose first byte arrived at `t_ns`, the
/// bytes `per_byte_ns` apart. The one conversion from receive timestamps to `t_s`: the
/// simulator's ground truth uses it too, so that the two agree to the last bit.
pub fn byte_time_s(t_ns: u64, i: usize, per_byte_ns: f64) -> f64 {
    (t_ns as f64 + i as f64 * per_byte_ns) * 1e-9
}

/// Appends to `times` the receive times, in Unix seconds, of `n` bytes the first of which
/// arrived at `t_ns` (Unix ns) and each next one `per_byte_ns` later (a byte time at the line's
/// baud rate: bytes of one read arrived back to back). The one place where a chunk's receive
/// time becomes the time of each of its bytes.
pub fn byte_times(t_ns: u64, per_byte_ns: f64, n: usize, times: &mut Vec<f64>) {
    times.extend((0..n).map(|i| byte_time_s(t_ns, i, per_byte_ns)));
}

/// The longest step between two frames of one ESC that is always time passing at the frame
/// rate: 20 frame periods (an idle ESC sends a frame every ~364 ms, a read may return a
/// little late). The same second after which the stream tells the decoder of a silence
/// ([`crate::SILENCE_S`]).
pub const MAX_STEP_S: f64 = 1.0;

/// The longest time an ESC takes per data frame it counts in its packet number, s: an idle
/// ESC sends one every ~364 ms, a running one every ~56 ms.
pub const MAX_FRAME_SPACING_S: f64 = 0.5;

/// What the receive times of two consecutive data frames of one ESC say: the one definition
/// of a clock discontinuity that the summary's duration, the energy integration, the plot's
/// time axis and the bridge's replay use.
///
/// A step back in time, or a step forward longer than [`MAX_STEP_S`] plus
/// [`MAX_FRAME_SPACING_S`] per packet the ESC counted meanwhile, is a discontinuity of the
/// receive clock (a clock set back by NTP, a computer that booted in 1970 and then synced),
/// not time that passed: nothing is integrated or counted across it. A longer step the packet
/// number explains is a [`Step::Silence`]: the line was cut while the ESC ran on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    /// Time passing at the frame rate: at most [`MAX_STEP_S`], not back.
    Continuous(f64),
    /// Longer than [`MAX_STEP_S`], but no longer than the packets the ESC counted meanwhile
    /// take: frames lost, time passed.
    Silence(f64),
    /// The clock went back.
    Back,
    /// The clock jumped forward by more than the ESC's packets explain.
    Jump,
}

impl Step {
    /// The step from a frame received at `from` to one received at `to` (s); `packets` is
    /// how far the packet number advanced between them (wrapping), where both are data frames
    /// of one ESC. Without it, a step longer than [`MAX_STEP_S`] is a [`Step::Jump`].
    pub fn between(from: f64, to: f64, packets: Option<u32>) -> Step {
        let dt = to - from;
        if dt.is_nan() || dt < 0.0 {
            return Step::Back;
        }
        if dt <= MAX_STEP_S {
            return Step::Continuous(dt);
        }
        match packets {
            Some(n) if dt <= MAX_STEP_S + f64::from(n) * MAX_FRAME_SPACING_S => Step::Silence(dt),
            _ => Step::Jump,
        }
    }

    /// The time that passed: the step, or nothing across a discontinuity.
    pub fn elapsed(self) -> Option<f64> {
        match self {
            Step::Continuous(dt) | Step::Silence(dt) => Some(dt),
            Step::Back | Step::Jump => None,
        }
    }

    /// Whether the clock stepped back or jumped.
    pub fn is_discontinuity(self) -> bool {
        self.elapsed().is_none()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_back_and_unexplained_jumps_are_discontinuities() {
        assert_eq!(
            Step::between(10.0, 10.05, Some(1)),
            Step::Continuous(10.05 - 10.0)
        );
        assert_eq!(Step::between(10.0, 10.0, Some(0)), Step::Continuous(0.0));
        assert_eq!(Step::between(10.0, 9.99, Some(1)), Step::Back);
        assert_eq!(Step::between(10.0, f64::NAN, Some(1)), Step::Back);
        // An idle ESC: one frame every 364 ms, one lost.
        assert_eq!(Step::between(0.0, 0.728, Some(2)), Step::Continuous(0.728));
        // A minute's cut line while the ESC counted 1200 frames: time passed.
        assert_eq!(Step::between(0.0, 60.0, Some(1200)), Step::Silence(60.0));
        // A minute after the next packet: the clock jumped.
        assert_eq!(Step::between(0.0, 60.0, Some(1)), Step::Jump);
        // 200 years later.
        assert_eq!(Step::between(1.8e9, 8.0e9, Some(1)), Step::Jump);
        assert_eq!(Step::between(0.0, 2.0, None), Step::Jump);
        assert!(Step::Back.is_discontinuity() && Step::Jump.is_discontinuity());
        assert_eq!(Step::Silence(60.0).elapsed(), Some(60.0));
    }
}
