//! Alarms: when a reading or a status bit becomes a warning or critical, and when it is over.
//!
//! Every alarm is a latch that fires once per episode and clears with hysteresis, so that a
//! value hovering at a threshold or a bit that comes and goes between frames does not flicker:
//! - a threshold ([`Threshold`]) enters a level when the value reaches it and leaves it only
//!   once the value is back past the level by the hysteresis or more (degrees, volts): with a
//!   warning at 90 degC and 5 degC of hysteresis, the warning is raised at 90 and cleared at 85;
//! - a status bit, a stale ESC or a lost port ([`Latch::set`]) raises at once and clears only
//!   after it has stayed off for a hold time.
//!
//! A latch reports [`Change`]s: raised (the episode starts, with its level), escalated (warning
//! to critical within the episode) and cleared (with its duration). A critical alarm easing back
//! to a warning is not news: the episode goes on at the higher level it reached.

use std::fmt;

use hwfoc::Protocol;
use hwfoc::format::Severity;

/// A fault bit of a protocol's fault word (HW-FOC's sixteen status bits, HW5's eight fault
/// bits: [`Protocol::fault_name`]): the same bit means another fault in another protocol.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FaultBit {
    /// The protocol whose word it is.
    pub protocol: Protocol,
    /// The bit, 0 to 15.
    pub bit: u8,
}

/// How bad an alarm is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Level {
    /// Worth watching.
    Warning,
    /// Act now.
    Critical,
}

impl Level {
    /// `warning` or `critical`.
    pub fn name(self) -> &'static str {
        match self {
            Level::Warning => "warning",
            Level::Critical => "critical",
        }
    }
}

impl fmt::Display for Level {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What an alarm is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Kind {
    /// A fault bit the ESC reports.
    Fault(FaultBit),
    /// MOSFET temperature over a threshold.
    MosTemp,
    /// Capacitor temperature over a threshold.
    CapTemp,
    /// Battery voltage under a threshold.
    LowVoltage,
    /// No frame for longer than the stale time while the port is open.
    Stale,
    /// The port is gone (adapter unplugged).
    Disconnected,
}

impl Kind {
    /// The alarm's name in logs and JSON: a fault bit's name as its protocol names it
    /// (HW-FOC's as in docs/PROTOCOL-NOTES.md, `mos_overheat`; HW5's as in
    /// docs/HW5-AND-CAN.md, `motor_locked`), or `mos_temp`, `cap_temp`, `low_voltage`, `stale`,
    /// `disconnected`.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Fault(f) => f.protocol.fault_name(f.bit).unwrap_or("unknown_fault"),
            Kind::MosTemp => "mos_temp",
            Kind::CapTemp => "cap_temp",
            Kind::LowVoltage => "low_voltage",
            Kind::Stale => "stale",
            Kind::Disconnected => "disconnected",
        }
    }

    /// The level of a fault-bit alarm: the severity its protocol's description gives the bit
    /// ([`hwfoc::format::FaultDescription::severity`]); a bit it does not define is a warning.
    pub fn fault_level(f: FaultBit) -> Level {
        let severity = f
            .protocol
            .description()
            .fault(f.bit)
            .map_or(Severity::UNKNOWN, |d| d.severity);
        match severity {
            Severity::Warning => Level::Warning,
            Severity::Critical => Level::Critical,
        }
    }
}

/// What happened to an alarm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Change {
    /// An episode starts at this level.
    Raised(Level),
    /// The episode went from warning to critical.
    Escalated,
    /// The episode is over after this many seconds; `worst` is the extreme value it saw
    /// (for thresholds; `None` for bits).
    Cleared {
        /// The highest level the episode reached (what it is cleared from).
        level: Level,
        /// Seconds from raised to cleared.
        duration_s: f64,
        /// The highest (or, for low voltage, lowest) value of the episode.
        worst: Option<f64>,
    },
}

/// Two levels on one quantity, bad when high (temperatures) or when low (voltage).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Threshold {
    /// The warning level.
    pub warning: f64,
    /// The critical level (beyond the warning level).
    pub critical: f64,
    /// How far back past a level the value must go to leave it.
    pub hysteresis: f64,
    /// Whether low values are the bad ones.
    pub low_is_bad: bool,
}

impl Threshold {
    /// A limit on a value that is bad when high.
    pub fn high(warning: f64, critical: f64, hysteresis: f64) -> Threshold {
        Threshold {
            warning,
            critical,
            hysteresis,
            low_is_bad: false,
        }
    }

    /// A limit on a value that is bad when low.
    pub fn low(warning: f64, critical: f64, hysteresis: f64) -> Threshold {
        Threshold {
            warning,
            critical,
            hysteresis,
            low_is_bad: true,
        }
    }

    /// `value` turned so that higher is always worse.
    fn badness(&self, value: f64) -> (f64, f64, f64) {
        if self.low_is_bad {
            (-value, -self.warning, -self.critical)
        } else {
            (value, self.warning, self.critical)
        }
    }

    /// The level `value` is at on its own, without history (for colouring a cell).
    pub fn level_of(&self, value: f64) -> Option<Level> {
        let (v, warning, critical) = self.badness(value);
        if v >= critical {
            Some(Level::Critical)
        } else if v >= warning {
            Some(Level::Warning)
        } else {
            None
        }
    }

    /// The level after `value`, coming from `level`: a level is entered at its threshold and
    /// left once the value is `hysteresis` back past it.
    fn next(&self, level: Option<Level>, value: f64) -> Option<Level> {
        let (v, warning, critical) = self.badness(value);
        let h = self.hysteresis;
        let held = match level {
            Some(Level::Critical) if v > critical - h => Some(Level::Critical),
            Some(_) if v > warning - h => Some(Level::Warning),
            _ => None,
        };
        held.max(self.level_of(value))
    }
}

/// One alarm's state: its level in the current episode, when the episode started, and its
/// worst value.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Latch {
    level: Option<Level>,
    /// The highest level of the episode (what the log reported).
    reported: Option<Level>,
    since: f64,
    worst: Option<f64>,
    /// When a bit alarm's condition was last seen on.
    last_on: f64,
}

impl Latch {
    /// The current level, `None` when clear.
    pub fn level(&self) -> Option<Level> {
        self.level
    }

    /// Feeds a reading at time `t` (seconds) against `threshold`.
    pub fn update(&mut self, threshold: &Threshold, value: f64, t: f64) -> Option<Change> {
        let next = threshold.next(self.level, value);
        if next.is_some() {
            let worse = |w: f64| {
                if threshold.low_is_bad {
                    value < w
                } else {
                    value > w
                }
            };
            if self.worst.is_none_or(worse) {
                self.worst = Some(value);
            }
        }
        self.move_to(next, t)
    }

    /// Feeds an on/off condition at time `t`: on raises at `level` at once; it clears after it
    /// has been off for `hold_s` seconds.
    pub fn set(&mut self, on: bool, level: Level, hold_s: f64, t: f64) -> Option<Change> {
        if on {
            self.last_on = t;
            self.move_to(Some(level.max(self.level.unwrap_or(level))), t)
        } else if self.level.is_some() && t - self.last_on >= hold_s - 1e-9 {
            self.move_to(None, t)
        } else {
            None
        }
    }

    /// Ends the episode now, whatever the value (the reading is no longer available: the ESC
    /// went silent or was reset).
    pub fn clear(&mut self, t: f64) -> Option<Change> {
        self.move_to(None, t)
    }

    fn move_to(&mut self, next: Option<Level>, t: f64) -> Option<Change> {
        let change = match (self.reported, next) {
            (None, Some(level)) => {
                self.since = t;
                self.reported = Some(level);
                Some(Change::Raised(level))
            }
            (Some(Level::Warning), Some(Level::Critical)) => {
                self.reported = Some(Level::Critical);
                Some(Change::Escalated)
            }
            (Some(level), None) => {
                self.reported = None;
                let worst = self.worst.take();
                Some(Change::Cleared {
                    level,
                    duration_s: (t - self.since).max(0.0),
                    worst,
                })
            }
            _ => None,
        };
        self.level = next;
        change
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::Fault;

    fn run(latch: &mut Latch, th: &Threshold, values: &[f64]) -> Vec<(usize, Change)> {
        values
            .iter()
            .enumerate()
            .filter_map(|(i, &v)| latch.update(th, v, i as f64).map(|c| (i, c)))
            .collect()
    }

    #[test]
    fn a_temperature_hovering_at_the_warning_level_fires_once() {
        let th = Threshold::high(90.0, 105.0, 5.0);
        let mut latch = Latch::default();
        let values = [
            80.0, 89.0, 90.0, 89.0, 90.5, 86.0, 91.0, 88.0, 85.1, 85.0, 80.0,
        ];
        let changes = run(&mut latch, &th, &values);
        assert_eq!(
            changes,
            vec![
                (2, Change::Raised(Level::Warning)),
                (
                    9,
                    Change::Cleared {
                        level: Level::Warning,
                        duration_s: 7.0,
                        worst: Some(91.0)
                    }
                ),
            ]
        );
        assert_eq!(latch.level(), None);
    }

    #[test]
    fn warning_escalates_to_critical_and_does_not_report_easing_back() {
        let th = Threshold::high(90.0, 105.0, 5.0);
        let mut latch = Latch::default();
        let values = [95.0, 106.0, 101.0, 104.0, 99.0, 106.0, 95.0, 84.0];
        let changes = run(&mut latch, &th, &values);
        assert_eq!(
            changes,
            vec![
                (0, Change::Raised(Level::Warning)),
                (1, Change::Escalated),
                (
                    7,
                    Change::Cleared {
                        level: Level::Critical,
                        duration_s: 7.0,
                        worst: Some(106.0)
                    }
                ),
            ]
        );
    }

    #[test]
    fn levels_follow_hysteresis_within_an_episode() {
        let th = Threshold::high(90.0, 105.0, 5.0);
        let mut latch = Latch::default();
        let mut levels = Vec::new();
        for v in [106.0, 101.0, 100.1, 100.0, 104.0, 85.1, 85.0] {
            latch.update(&th, v, 0.0);
            levels.push(latch.level());
        }
        use Level::*;
        assert_eq!(
            levels,
            [
                Some(Critical),
                Some(Critical),
                Some(Critical),
                Some(Warning),
                Some(Warning),
                Some(Warning),
                None
            ]
        );
    }

    #[test]
    fn a_jump_straight_to_critical_is_one_raise() {
        let th = Threshold::high(90.0, 105.0, 5.0);
        let mut latch = Latch::default();
        let changes = run(&mut latch, &th, &[20.0, 110.0, 20.0]);
        assert_eq!(changes[0], (1, Change::Raised(Level::Critical)));
        assert_eq!(changes.len(), 2);
    }

    #[test]
    fn low_voltage_is_bad_when_low_and_reports_the_lowest_value() {
        let th = Threshold::low(21.0, 19.8, 0.6);
        let mut latch = Latch::default();
        let values = [24.0, 20.9, 21.3, 21.5, 19.7, 20.5, 21.5, 21.6];
        let changes = run(&mut latch, &th, &values);
        assert_eq!(
            changes,
            vec![
                (1, Change::Raised(Level::Warning)),
                (4, Change::Escalated),
                (
                    7,
                    Change::Cleared {
                        level: Level::Critical,
                        duration_s: 6.0,
                        worst: Some(19.7)
                    }
                ),
            ]
        );
        assert_eq!(th.level_of(20.0), Some(Level::Warning));
        assert_eq!(th.level_of(19.8), Some(Level::Critical));
        assert_eq!(th.level_of(22.0), None);
    }

    #[test]
    fn a_bit_that_flickers_stays_one_episode_until_off_for_the_hold_time() {
        let mut latch = Latch::default();
        let mut changes = Vec::new();
        // Frames every 0.05 s: the bit is on every other frame for 1 s, then off.
        for i in 0..60 {
            let t = i as f64 * 0.05;
            let on = i < 20 && i % 2 == 0;
            if let Some(c) = latch.set(on, Level::Critical, 0.5, t) {
                changes.push((i, c));
            }
        }
        assert_eq!(changes.len(), 2, "{changes:?}");
        assert_eq!(changes[0], (0, Change::Raised(Level::Critical)));
        // Last on at frame 18 (0.9 s): cleared at the first frame 0.5 s later, frame 28.
        match changes[1] {
            (
                28,
                Change::Cleared {
                    level: Level::Critical,
                    duration_s,
                    worst,
                },
            ) => {
                assert!((duration_s - 1.4).abs() < 1e-9);
                assert_eq!(worst, None);
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_clear_names_the_highest_level_of_its_episode() {
        let th = Threshold::high(90.0, 105.0, 5.0);
        // Raised critical, eased to warning, then cleared: cleared from critical.
        let mut latch = Latch::default();
        let changes = run(&mut latch, &th, &[110.0, 95.0, 80.0]);
        assert_eq!(changes[0], (0, Change::Raised(Level::Critical)));
        assert!(
            matches!(
                changes[1],
                (
                    2,
                    Change::Cleared {
                        level: Level::Critical,
                        ..
                    }
                )
            ),
            "{changes:?}"
        );
        // A bit raised critical and cleared by `clear` (the ESC went silent).
        let mut latch = Latch::default();
        latch.set(true, Level::Critical, 0.5, 0.0);
        assert!(matches!(
            latch.clear(1.0),
            Some(Change::Cleared {
                level: Level::Critical,
                ..
            })
        ));
        // A warning stays a warning.
        let mut latch = Latch::default();
        let changes = run(&mut latch, &th, &[95.0, 80.0]);
        assert!(matches!(
            changes[1].1,
            Change::Cleared {
                level: Level::Warning,
                ..
            }
        ));
    }

    #[test]
    fn clear_ends_an_episode_once() {
        let th = Threshold::high(90.0, 105.0, 5.0);
        let mut latch = Latch::default();
        assert_eq!(latch.clear(0.0), None);
        latch.update(&th, 95.0, 1.0);
        assert!(matches!(latch.clear(3.0), Some(Change::Cleared { .. })));
        assert_eq!(latch.clear(4.0), None);
        // A new episode after a clear is reported again.
        assert_eq!(
            latch.update(&th, 95.0, 5.0),
            Some(Change::Raised(Level::Warning))
        );
    }

    #[test]
    fn fault_levels() {
        let foc = |f: Fault| FaultBit {
            protocol: Protocol::HwFoc,
            bit: f.bit(),
        };
        assert_eq!(Kind::fault_level(foc(Fault::MosOverheat)), Level::Critical);
        assert_eq!(
            Kind::fault_level(foc(Fault::ThrottleSignalLost)),
            Level::Warning
        );
        assert_eq!(Kind::Fault(foc(Fault::MosOverheat)).name(), "mos_overheat");
        // HW5's bits are HW5's faults: bit 5 is its low voltage (a warning), not HW-FOC's.
        let hw5 = |bit| FaultBit {
            protocol: Protocol::Hw5,
            bit,
        };
        assert_eq!(Kind::Fault(hw5(5)).name(), "low_voltage");
        assert_eq!(Kind::fault_level(hw5(5)), Level::Warning);
        assert_eq!(Kind::Fault(hw5(0)).name(), "motor_locked");
        assert_eq!(Kind::fault_level(hw5(0)), Level::Critical);
    }
}
