//! A whole run: a fleet, its destination, the ground truth, the clock and how long it lasts
//! ([`Plan`]), opened ([`Session::open`]) and run ([`Session::run`]) to a report per ESC.
//!
//! The ground truth has one record per data frame delivered intact, `t_s` being the time its
//! first byte started on the wire, in the clock of the output:
//! - real-time outputs (pseudo-terminals, serial ports, [`Plan::realtime`]): Unix time;
//! - a pcapng recording: the recording's own timestamps, which start at [`Plan::start_s`]
//!   (Unix seconds; default now), so that decoding the recording gives exactly the truth's
//!   `t_s`;
//! - raw bytes (a file or standard output): raw bytes carry no time, so decoding them gives a
//!   null `t_s`; the truth still has the simulated time, seconds from the start of the run plus
//!   [`Plan::start_s`] (default 0).

use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use hwfoc::Settings;
use hwfoc_ports::clock::unix_now_ns;

use crate::destination::{Destination, FileFormat, Opened};
use crate::error::SimError;
use crate::esc::VirtualEsc;
use crate::fleet::VirtualFleet;
use crate::schedule::{self, Pace, SimClock, Tally};
use crate::sink::{self, Truth};

/// Extra seconds after one run of the profile, for runs written at once without a duration:
/// the motor stops and the idle frames and device information show.
pub(crate) const TAIL_S: f64 = 2.0;
/// How long the ptys stay open after the last write.
pub(crate) const PTY_LINGER: Duration = Duration::from_millis(300);

/// How a fleet is run: where its bytes go, at what rate, from when, for how long, and where
/// the ground truth goes.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Where the bytes go.
    pub destination: Destination,
    /// Write a file or standard output at the real rate instead of as fast as possible (live
    /// destinations always are).
    pub realtime: bool,
    /// Unix time (seconds) of the start, for runs written at once: the recording's clock and
    /// the truth's. Default: now for pcapng, 0 for raw bytes. Real-time runs use the time now.
    pub start_s: Option<f64>,
    /// Seconds of simulated time. Default: one run of the profile plus 2 s for runs written at
    /// once; until stopped in real time.
    pub duration_s: Option<f64>,
    /// The ground truth's file (`-`: standard output), if wanted.
    pub truth: Option<String>,
    /// How the truth's records are converted (the ESCs' current scale and pole pairs should
    /// match the fleet's).
    pub settings: Settings,
    /// Replace output files (recordings, raw files, the truth) that exist. Without it, an
    /// existing file is an error ([`WriteError::Exists`](hwfoc_io::write::WriteError)) and
    /// nothing is written.
    pub overwrite: bool,
}

impl Plan {
    /// Whether the run goes at the real rate.
    pub fn is_realtime(&self) -> bool {
        self.realtime || self.destination.is_live()
    }
}

/// What one ESC sent, at the end of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct EscReport {
    /// Its output, as a person would name it (a path, a port, standard output).
    pub output: String,
    /// The id in its device information (empty for a protocol whose ESCs send none: all but
    /// HW-FOC).
    pub id: String,
    /// What it sent.
    pub tally: Tally,
    /// Bytes that could not be delivered (no reader on a pseudo-terminal, a port that would
    /// not take them).
    pub undelivered_bytes: u64,
}

/// A run with its outputs open, ready to start.
pub struct Session {
    escs: Vec<VirtualEsc>,
    opened: Opened,
    truth: Option<Truth>,
    pace: Pace,
    origin_ns: u64,
    realtime: bool,
    duration_ns: Option<u64>,
}

impl Session {
    /// Opens what `plan` asks for `fleet`: the ground truth first (so that a path that cannot
    /// be written is reported before any pseudo-terminal exists), then the destination.
    pub fn open(fleet: VirtualFleet, plan: &Plan) -> Result<Session, SimError> {
        let realtime = plan.is_realtime();
        let n = fleet.spec().n;
        let baud = fleet.spec().baud;
        let seed = fleet.spec().seed;
        let duration_s = match plan.duration_s {
            Some(d) => Some(d),
            None if realtime => None,
            None => Some(fleet.profile().natural_length_s() + TAIL_S),
        };
        let notes: Vec<String> = fleet
            .spec()
            .degradations
            .iter()
            .map(|d| d.truth_line())
            .collect();
        let escs = fleet.escs();
        // Every file is checked before any is created: a run fails whole or starts whole.
        let destination_files = plan.destination.files(n);
        let files = plan.truth.iter().chain(&destination_files);
        sink::check_new(files.map(String::as_str), plan.overwrite)?;
        let truth = match &plan.truth {
            Some(path) => {
                let (name, out) = sink::create(path, plan.overwrite)?;
                let mut truth = Truth::new(name, out, plan.settings);
                for note in &notes {
                    truth.note(note)?;
                }
                Some(truth)
            }
            None => None,
        };
        let start_ns = plan.start_s.map(|s| (s * 1e9).round() as u64);
        let origin_ns = match (realtime, plan.destination.file_format()) {
            (false, Some(FileFormat::Pcapng)) => start_ns.unwrap_or_else(unix_now_ns),
            (false, Some(FileFormat::Raw)) => start_ns.unwrap_or(0),
            _ => unix_now_ns(),
        };
        // The recording's id, from what makes its bytes: the same seed and start, the same id.
        let recording = hwfoc_io::pcapng::RecordingId::derived(&[seed, origin_ns]);
        Ok(Session {
            opened: plan.destination.open(
                n,
                (baud, escs.first().map(VirtualEsc::protocol)),
                plan.overwrite,
                recording,
            )?,
            escs,
            truth,
            pace: plan.destination.pace(realtime, baud),
            origin_ns,
            realtime,
            duration_ns: duration_s.map(|s| (s * 1e9).round() as u64),
        })
    }

    /// Each ESC's output, as a person would name it: for pseudo-terminals, the path to open.
    pub fn outputs(&self) -> &[String] {
        &self.opened.names
    }

    /// Runs to the end (of the duration, or until `stop` is set) and reports on each ESC.
    pub fn run(self, stop: &AtomicBool) -> Result<Vec<EscReport>, SimError> {
        let Session {
            escs,
            mut opened,
            mut truth,
            pace,
            origin_ns,
            realtime,
            duration_ns,
        } = self;
        // The ESC's id, where its format's device information has one (HW-FOC's).
        let ids: Vec<String> = escs
            .iter()
            .map(|e| {
                let has_id = e.protocol().description().info_keys.contains(&"id");
                if has_id {
                    e.info().id().to_string()
                } else {
                    String::new()
                }
            })
            .collect();
        let clock = SimClock {
            origin_ns,
            real: realtime.then(Instant::now),
        };
        let tallies = schedule::run(
            escs,
            opened.sink.as_mut(),
            truth.as_mut(),
            pace,
            clock,
            duration_ns,
            stop,
        )?;
        if opened.linger {
            // Closing a pty's master hangs up the reader and discards what it has not read
            // yet: give readers a moment to take the last frames, which the truth lists as
            // delivered.
            std::thread::sleep(PTY_LINGER);
        }
        Ok(tallies
            .into_iter()
            .zip(ids)
            .enumerate()
            .map(|(esc, (tally, id))| EscReport {
                output: opened.names[esc].clone(),
                id,
                tally,
                undelivered_bytes: opened.sink.undelivered(esc),
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fleet::tests::spec;
    use hwfoc_io::write::WriteError;

    #[test]
    fn a_recording_is_the_same_every_time_and_its_truth_matches_the_report() {
        let dir = tempfile::tempdir().unwrap();
        let path = |name: &str| dir.path().join(name).display().to_string();
        let run = |name: &str| {
            let plan = Plan {
                destination: Destination::File {
                    path: path(name),
                    format: FileFormat::for_path(name),
                },
                realtime: false,
                start_s: Some(1.7e9),
                duration_s: None,
                truth: Some(path(&format!("{name}.jsonl"))),
                settings: Settings::default(),
                overwrite: false,
            };
            let session = Session::open(spec(2).build().unwrap(), &plan).unwrap();
            assert_eq!(session.outputs(), [path(name), path(name)]);
            let reports = session.run(&AtomicBool::new(false)).unwrap();
            let truth = std::fs::read_to_string(path(&format!("{name}.jsonl"))).unwrap();
            (std::fs::read(path(name)).unwrap(), reports, truth)
        };
        let (a, reports, truth) = run("a.pcapng");
        let (b, again, _) = run("b.pcapng");
        assert_eq!(a, b);
        let tallies = |r: &[EscReport]| -> Vec<(String, Tally)> {
            r.iter().map(|r| (r.id.clone(), r.tally.clone())).collect()
        };
        assert_eq!(tallies(&reports), tallies(&again));
        let intact: u64 = reports.iter().map(|r| r.tally.intact).sum();
        assert_eq!(truth.lines().count() as u64, intact);
        // The profile's 2.5 s and 2 s more: idle, then running at 50 %.
        assert!(reports.iter().all(|r| (40..90).contains(&r.tally.data)));
        let first: serde_json::Value = serde_json::from_str(truth.lines().next().unwrap()).unwrap();
        assert!((1.7e9..1.7e9 + 0.05).contains(&first["t_s"].as_f64().unwrap()));
    }

    #[test]
    fn an_existing_file_is_never_written_over_unasked() {
        let dir = tempfile::tempdir().unwrap();
        let path = |name: &str| dir.path().join(name).display().to_string();
        // ESC 1's file exists (an earlier run's); ESC 0's and the truth do not.
        std::fs::write(path("esc1.bin"), b"an earlier recording").unwrap();
        let plan = |overwrite| Plan {
            destination: Destination::File {
                path: path("esc{esc}.bin"),
                format: FileFormat::Raw,
            },
            realtime: false,
            start_s: None,
            duration_s: Some(1.0),
            truth: Some(path("truth.jsonl")),
            settings: Settings::default(),
            overwrite,
        };
        let e = Session::open(spec(2).build().unwrap(), &plan(false))
            .err()
            .unwrap();
        assert!(
            matches!(&e, SimError::Write(WriteError::Exists { output }) if *output == path("esc1.bin")),
            "{e}"
        );
        // The library names no option of a front end (the command adds "or pass --overwrite").
        assert!(!e.to_string().contains("--"), "{e}");
        // Nothing was created or touched: the run failed whole.
        assert_eq!(
            std::fs::read(path("esc1.bin")).unwrap(),
            b"an earlier recording"
        );
        assert!(!std::path::Path::new(&path("esc0.bin")).exists());
        assert!(!std::path::Path::new(&path("truth.jsonl")).exists());

        // The truth alone existing is refused as well.
        std::fs::remove_file(path("esc1.bin")).unwrap();
        std::fs::write(path("truth.jsonl"), b"{}\n").unwrap();
        let e = Session::open(spec(2).build().unwrap(), &plan(false))
            .err()
            .unwrap();
        assert!(
            matches!(&e, SimError::Write(WriteError::Exists { output }) if *output == path("truth.jsonl"))
        );
        assert_eq!(std::fs::read(path("truth.jsonl")).unwrap(), b"{}\n");

        // Asked: replaced.
        std::fs::write(path("esc1.bin"), b"an earlier recording").unwrap();
        let session = Session::open(spec(2).build().unwrap(), &plan(true)).unwrap();
        session.run(&AtomicBool::new(false)).unwrap();
        let bytes = std::fs::read(path("esc1.bin")).unwrap();
        assert!(
            bytes.len() >= 24 && !bytes.starts_with(b"an earlier"),
            "{bytes:?}"
        );
        assert_ne!(std::fs::read(path("truth.jsonl")).unwrap(), b"{}\n");
    }

    #[test]
    fn raw_bytes_of_several_escs_need_a_file_each() {
        let dir = tempfile::tempdir().unwrap();
        let plan = Plan {
            destination: Destination::File {
                path: dir.path().join("x.bin").display().to_string(),
                format: FileFormat::Raw,
            },
            realtime: false,
            start_s: None,
            duration_s: Some(1.0),
            truth: None,
            settings: Settings::default(),
            overwrite: false,
        };
        let e = Session::open(spec(2).build().unwrap(), &plan)
            .err()
            .unwrap();
        assert!(matches!(e, SimError::SharedRaw { n: 2 }), "{e}");
    }
}
