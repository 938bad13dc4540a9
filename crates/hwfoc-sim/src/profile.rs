//! Throttle profiles: what the pilot (or the test bench) asks of the virtual ESCs over time.
//!
//! Built-in profiles start with a lead-in at zero throttle (the ESC arms, sends idle frames and
//! device information), then repeat one cycle for as long as the simulation runs:
//! - `steps`: hold each of a list of levels in turn (abrupt changes: spin-ups, regenerative
//!   braking on the way down);
//! - `ramp`: a triangle from 0 up to a maximum and back over one period;
//! - `sine`: a smooth rise and fall, `max * (1 - cos(2 pi t / period)) / 2`.
//!
//! A CSV profile is taken literally: rows `time_s,throttle_percent`, linear between rows (two rows
//! at the same time make a step), the first value before the first row, the last one after it.

use std::fmt;
use std::str::FromStr;

use hwfoc_io::read_small_file;

use crate::error::SimError;

/// The largest throttle profile read (a point per line, a few tens of bytes each: a day of
/// points every 10 ms fits).
const MAX_PROFILE: u64 = 64 << 20;

/// A profile as named (`steps`, `ramp`, `sine`, `csv:FILE`), before any file is read.
#[derive(Debug, Clone, PartialEq)]
pub enum ProfileSpec {
    /// Hold each level for a while.
    Steps,
    /// Triangle up and down.
    Ramp,
    /// Smooth rise and fall.
    Sine,
    /// Rows of a CSV file.
    Csv(String),
}

impl FromStr for ProfileSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "steps" => Ok(ProfileSpec::Steps),
            "ramp" => Ok(ProfileSpec::Ramp),
            "sine" => Ok(ProfileSpec::Sine),
            _ => match s.strip_prefix("csv:") {
                Some(path) if !path.is_empty() => Ok(ProfileSpec::Csv(path.to_string())),
                _ => Err(format!(
                    "unknown profile {s:?}: expected steps, ramp, sine or csv:FILE"
                )),
            },
        }
    }
}

impl fmt::Display for ProfileSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ProfileSpec::Steps => f.write_str("steps"),
            ProfileSpec::Ramp => f.write_str("ramp"),
            ProfileSpec::Sine => f.write_str("sine"),
            ProfileSpec::Csv(path) => write!(f, "csv:{path}"),
        }
    }
}

/// The parameters of the built-in profiles.
#[derive(Debug, Clone, PartialEq)]
pub struct Shape {
    /// Seconds at zero throttle before the first cycle.
    pub lead_in_s: f64,
    /// `steps`: the levels, percent.
    pub levels: Vec<f64>,
    /// `steps`: seconds per level.
    pub hold_s: f64,
    /// `ramp`, `sine`: seconds per cycle.
    pub period_s: f64,
    /// `ramp`, `sine`: the highest throttle, percent.
    pub max_pct: f64,
}

/// A throttle command as a function of time.
#[derive(Debug, Clone, PartialEq)]
pub enum Profile {
    /// Levels held in turn after a lead-in.
    Steps {
        /// Seconds at zero first.
        lead_in_s: f64,
        /// Percent.
        levels: Vec<f64>,
        /// Seconds per level.
        hold_s: f64,
    },
    /// Triangle after a lead-in.
    Ramp {
        /// Seconds at zero first.
        lead_in_s: f64,
        /// Seconds per cycle.
        period_s: f64,
        /// Percent at the top.
        max_pct: f64,
    },
    /// Raised cosine after a lead-in.
    Sine {
        /// Seconds at zero first.
        lead_in_s: f64,
        /// Seconds per cycle.
        period_s: f64,
        /// Percent at the top.
        max_pct: f64,
    },
    /// Points `(time_s, percent)`, times non-decreasing, at least one.
    Points(Vec<(f64, f64)>),
}

impl Profile {
    /// The profile `spec` with parameters `shape`, reading a CSV file if named.
    pub fn load(spec: &ProfileSpec, shape: &Shape) -> Result<Profile, SimError> {
        let Shape {
            lead_in_s,
            hold_s,
            period_s,
            max_pct,
            ..
        } = *shape;
        Ok(match spec {
            ProfileSpec::Steps => Profile::Steps {
                lead_in_s,
                levels: shape.levels.clone(),
                hold_s,
            },
            ProfileSpec::Ramp => Profile::Ramp {
                lead_in_s,
                period_s,
                max_pct,
            },
            ProfileSpec::Sine => Profile::Sine {
                lead_in_s,
                period_s,
                max_pct,
            },
            ProfileSpec::Csv(path) => {
                let text =
                    read_small_file(path, MAX_PROFILE).map_err(|source| SimError::ProfileRead {
                        file: path.clone(),
                        source,
                    })?;
                Profile::Points(parse_csv(path, &text)?)
            }
        })
    }

    /// Throttle in percent (0..=100) at `t` seconds.
    pub fn throttle(&self, t: f64) -> f64 {
        let pct = match self {
            Profile::Steps {
                lead_in_s,
                levels,
                hold_s,
            } => {
                if t < *lead_in_s || levels.is_empty() {
                    0.0
                } else {
                    let i = ((t - lead_in_s) / hold_s) as usize % levels.len();
                    levels[i]
                }
            }
            Profile::Ramp {
                lead_in_s,
                period_s,
                max_pct,
            } => phase(t, *lead_in_s, *period_s)
                .map_or(0.0, |phase| max_pct * (1.0 - (2.0 * phase - 1.0).abs())),
            Profile::Sine {
                lead_in_s,
                period_s,
                max_pct,
            } => phase(t, *lead_in_s, *period_s).map_or(0.0, |phase| {
                max_pct * (1.0 - (std::f64::consts::TAU * phase).cos()) / 2.0
            }),
            Profile::Points(points) => interpolate(points, t),
        };
        pct.clamp(0.0, 100.0)
    }

    /// Seconds of one natural run: lead-in plus one cycle, or up to the last CSV row.
    pub fn natural_length_s(&self) -> f64 {
        match self {
            Profile::Steps {
                lead_in_s,
                levels,
                hold_s,
            } => lead_in_s + hold_s * levels.len() as f64,
            Profile::Ramp {
                lead_in_s,
                period_s,
                ..
            }
            | Profile::Sine {
                lead_in_s,
                period_s,
                ..
            } => lead_in_s + period_s,
            Profile::Points(points) => points.last().map_or(0.0, |p| p.0),
        }
    }
}

/// Where `t` is in a cycle of `period_s` seconds that starts after `lead_in_s` (0..1), or
/// `None` during the lead-in.
fn phase(t: f64, lead_in_s: f64, period_s: f64) -> Option<f64> {
    (t >= lead_in_s).then(|| ((t - lead_in_s) / period_s).fract())
}

/// Linear interpolation between points sorted by time; constant outside them.
fn interpolate(points: &[(f64, f64)], t: f64) -> f64 {
    // The last point at or before t.
    let after = points.partition_point(|p| p.0 <= t);
    match (after.checked_sub(1).map(|i| points[i]), points.get(after)) {
        (None, Some(first)) => first.1,
        (Some(last), None) => last.1,
        (Some((t0, v0)), Some(&(t1, v1))) => v0 + (v1 - v0) * (t - t0) / (t1 - t0),
        (None, None) => 0.0,
    }
}

/// Reads CSV rows `time_s,throttle_percent`. A first line that is not two numbers is a header;
/// blank lines and lines starting with `#` are skipped.
pub fn parse_csv(name: &str, text: &[u8]) -> Result<Vec<(f64, f64)>, SimError> {
    let bad = |line: u64, message: String| SimError::Profile {
        file: name.to_string(),
        line,
        message,
    };
    let text = std::str::from_utf8(text).map_err(|e| {
        let line = text[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count() as u64
            + 1;
        bad(line, "not valid UTF-8 text".to_string())
    })?;
    let mut points: Vec<(f64, f64)> = Vec::new();
    let mut seen_line = false;
    for (i, raw) in text.lines().enumerate() {
        let line = i as u64 + 1;
        let row = raw.trim().trim_start_matches('\u{FEFF}');
        if row.is_empty() || row.starts_with('#') {
            continue;
        }
        let first_line = !seen_line;
        seen_line = true;
        let fields: Vec<&str> = row.split(',').map(|f| f.trim().trim_matches('"')).collect();
        let numbers: Vec<Option<f64>> = fields.iter().map(|f| f.parse::<f64>().ok()).collect();
        if first_line && numbers.iter().all(Option::is_none) {
            continue; // a header row
        }
        if fields.len() != 2 {
            return Err(bad(
                line,
                format!(
                    "expected 2 fields (time_s,throttle_percent), found {}",
                    fields.len()
                ),
            ));
        }
        let time = numbers[0]
            .filter(|t| t.is_finite() && *t >= 0.0)
            .ok_or_else(|| {
                bad(
                    line,
                    format!("bad time {:?} (seconds, 0 or more)", fields[0]),
                )
            })?;
        let pct = numbers[1]
            .filter(|p| (0.0..=100.0).contains(p))
            .ok_or_else(|| {
                bad(
                    line,
                    format!("bad throttle {:?} (percent, 0 to 100)", fields[1]),
                )
            })?;
        if let Some(&(prev, _)) = points.last()
            && time < prev
        {
            return Err(bad(
                line,
                format!("time {time} is before the previous row's {prev}"),
            ));
        }
        points.push((time, pct));
    }
    if points.is_empty() {
        return Err(SimError::Profile {
            file: name.to_string(),
            line: 0,
            message: "no rows: expected lines of time_s,throttle_percent".to_string(),
        });
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape() -> Shape {
        Shape {
            lead_in_s: 1.0,
            levels: vec![0.0, 50.0, 100.0],
            hold_s: 2.0,
            period_s: 4.0,
            max_pct: 80.0,
        }
    }

    #[test]
    fn built_in_profiles() {
        let steps = Profile::load(&ProfileSpec::Steps, &shape()).unwrap();
        let at = |p: &Profile, t: f64| p.throttle(t);
        assert_eq!(at(&steps, 0.5), 0.0);
        assert_eq!(at(&steps, 1.5), 0.0);
        assert_eq!(at(&steps, 3.5), 50.0);
        assert_eq!(at(&steps, 5.0), 100.0);
        assert_eq!(at(&steps, 7.5), 0.0); // the cycle repeats
        assert_eq!(at(&steps, 9.0), 50.0);
        assert_eq!(steps.natural_length_s(), 7.0);

        let ramp = Profile::load(&ProfileSpec::Ramp, &shape()).unwrap();
        assert_eq!(at(&ramp, 0.9), 0.0);
        assert_eq!(at(&ramp, 1.0), 0.0);
        assert!((at(&ramp, 2.0) - 40.0).abs() < 1e-9);
        assert!((at(&ramp, 3.0) - 80.0).abs() < 1e-9);
        assert!((at(&ramp, 4.0) - 40.0).abs() < 1e-9);
        assert!(at(&ramp, 5.0).abs() < 1e-9);

        let sine = Profile::load(&ProfileSpec::Sine, &shape()).unwrap();
        assert_eq!(at(&sine, 1.0), 0.0);
        assert!((at(&sine, 2.0) - 40.0).abs() < 1e-9);
        assert!((at(&sine, 3.0) - 80.0).abs() < 1e-9);
        assert_eq!(sine.natural_length_s(), 5.0);
    }

    #[test]
    fn spec_parsing() {
        assert_eq!("ramp".parse::<ProfileSpec>(), Ok(ProfileSpec::Ramp));
        assert_eq!(
            "csv:a/b.csv".parse::<ProfileSpec>(),
            Ok(ProfileSpec::Csv("a/b.csv".into()))
        );
        assert!("csv:".parse::<ProfileSpec>().is_err());
        assert!("square".parse::<ProfileSpec>().is_err());
    }

    #[test]
    fn csv_rows_interpolate_and_hold() {
        let csv = b"time_s,throttle_percent\n# spin up\n0,0\n1,0\n2,50\n2,20\n\n4,20\n";
        let points = parse_csv("p.csv", csv).unwrap();
        let p = Profile::Points(points);
        assert_eq!(p.throttle(0.5), 0.0);
        assert_eq!(p.throttle(1.5), 25.0);
        assert_eq!(p.throttle(2.0), 20.0); // a step: the later row wins
        assert_eq!(p.throttle(3.0), 20.0);
        assert_eq!(p.throttle(100.0), 20.0);
        assert_eq!(p.natural_length_s(), 4.0);
        // No header, CRLF, one row.
        let p = Profile::Points(parse_csv("q", b"0.5, 30\r\n").unwrap());
        assert_eq!(p.throttle(0.0), 30.0);
    }

    #[test]
    fn bad_csv_names_the_line() {
        let cases: [(&[u8], &str); 6] = [
            (b"t,thr\n0,0\n1,abc\n", "p.csv:3: bad throttle \"abc\""),
            (b"0,0\n1,150\n", "p.csv:2: bad throttle \"150\""),
            (b"0,0\n-1,10\n", "p.csv:2: bad time \"-1\""),
            (b"0,0\n2,10\n1,10\n", "p.csv:3: time 1 is before"),
            (b"0,0,0\n", "p.csv:1: expected 2 fields"),
            (b"# nothing\n", "p.csv: no rows"),
        ];
        for (text, expected) in cases {
            let e = parse_csv("p.csv", text).unwrap_err().to_string();
            assert!(e.starts_with(expected), "{e:?} vs {expected:?}");
        }
        let e = parse_csv("p.csv", b"0,0\n1,\xFF\n")
            .unwrap_err()
            .to_string();
        assert_eq!(e, "p.csv:2: not valid UTF-8 text");
    }
}
