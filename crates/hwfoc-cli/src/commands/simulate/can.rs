//! `hwfoc simulate --protocol hw-can`: a CAN bus of virtual Hobbywing DroneCAN ESCs
//! ([`hwfoc_sim::can`]) into a candump log or a pcapng recording (`-o FILE`, or standard
//! output) or an SLCAN pseudo-terminal (`--pty`), with the ground truth of every transfer
//! (`--truth`). In a log or a recording a virtual controller asks for the ESCs' ids unless
//! `--no-ask-ids`.

use std::io::IsTerminal;

use hwfoc::Settings;
use hwfoc_sim::SimError;
use hwfoc_sim::can::{CanBus, CanDestination, CanPlan, CanReport, CanSession};
#[cfg(unix)]
use hwfoc_sim::pty::PtyLinks;

use super::{Format, SimulateArgs, usage};
use crate::config::Config;
use crate::error::CliError;

/// Runs the CAN bus the options describe.
pub fn run(args: &SimulateArgs, config: &Config, settings: Settings) -> Result<(), CliError> {
    if !args.port.is_empty() {
        return Err(usage(
            "--port",
            "a CAN bus goes to a candump log (-o) or an SLCAN pseudo-terminal (--pty)",
        ));
    }
    if args.baud.is_some() {
        return Err(usage(
            "--baud",
            "a CAN bus runs at 500 kbit/s; an SLCAN program sets the rate with S0..S8",
        ));
    }
    if args.format == Some(Format::Raw) {
        return Err(usage(
            "--format",
            "a CAN bus is written as a candump log (--format candump) or pcapng",
        ));
    }
    if args.pty && (args.format.is_some() || args.no_ask_ids) {
        let option = if args.no_ask_ids {
            "--no-ask-ids"
        } else {
            "--format"
        };
        return Err(usage(
            option,
            "only for a log (-o or standard output): on the pty the controller asks, or not",
        ));
    }
    let n = usize::from(args.escs.unwrap_or(1));
    let destination = if args.pty {
        #[cfg(unix)]
        {
            CanDestination::Pty(match &args.link_dir {
                Some(dir) => PtyLinks::Dir(dir.clone()),
                None => PtyLinks::Paths(args.link.clone()),
            })
        }
        #[cfg(not(unix))]
        return Err(usage("--pty", "pseudo-terminals need a Unix system"));
    } else {
        let path = args.output.clone().unwrap_or_else(|| "-".to_string());
        let pcapng = match args.format {
            Some(f) => f == Format::Pcapng,
            None => path.ends_with(".pcapng"),
        };
        if pcapng && path == "-" && std::io::stdout().is_terminal() {
            return Err(usage(
                "--format",
                "not writing a pcapng recording to a terminal: give -o FILE, or pipe the output \
                 (e.g. into `hwfoc decode -`)",
            ));
        }
        if pcapng {
            CanDestination::Pcapng(path)
        } else {
            CanDestination::Candump(path)
        }
    };
    let plan = CanPlan {
        destination,
        realtime: args.realtime,
        start_s: args.start_time,
        duration_s: args.duration,
        truth: args.truth.clone(),
        overwrite: args.overwrite,
        ask_ids: !args.no_ask_ids,
    };
    if args.pty && args.start_time.is_some() {
        return Err(usage(
            "--start-time",
            "real-time outputs use the time now; --start-time is for files written at once",
        ));
    }
    // Outputs must not land on an input or on each other.
    let reads: Vec<std::path::PathBuf> = match &args.model.profile {
        hwfoc_sim::profile::ProfileSpec::Csv(path) => Some(std::path::PathBuf::from(path)),
        _ => None,
    }
    .into_iter()
    .chain(crate::safety::config_read(config))
    .collect();
    let outputs: Vec<&String> = match &plan.destination {
        CanDestination::Candump(path) | CanDestination::Pcapng(path) => vec![path],
        #[cfg(unix)]
        CanDestination::Pty(_) => vec![],
    };
    for out in outputs.iter().copied().chain(&plan.truth) {
        crate::safety::refuse_input(out, reads.iter().map(std::path::PathBuf::as_path))?;
    }
    if let (Some(truth), [log]) = (&plan.truth, outputs.as_slice())
        && crate::safety::same_output(truth, log)
    {
        return Err(usage(
            "--truth",
            format!("{truth} is also the output -o {log}: choose another file for either"),
        ));
    }
    // The serial ESCs' spec carries the model, profile and faults; the bus takes those.
    let spec = args.model.spec(n, 0, &settings);
    let bus = CanBus::build(&spec, args.factory).map_err(|e| match e {
        e @ SimError::CanDegradations => usage("--degrade", e.to_string()),
        e => CliError::from(e),
    })?;
    let session = CanSession::open(bus, &plan)?;
    if args.pty {
        announce_slcan(session.output())?;
    }
    let report = session.run(&crate::stop::interrupted())?;
    if !args.quiet {
        eprintln!("{}", line(n, &report));
    }
    Ok(())
}

/// Prints `slcan: PATH`: the pseudo-terminal to open as an SLCAN adapter.
fn announce_slcan(path: &str) -> Result<(), CliError> {
    use std::io::Write;
    let mut stdout = std::io::stdout().lock();
    writeln!(stdout, "slcan: {path}")
        .and_then(|()| stdout.flush())
        .map_err(|source| {
            hwfoc_io::write::WriteError::Write {
                output: "standard output".to_string(),
                source,
            }
            .into()
        })
}

/// The end-of-run line.
fn line(n: usize, r: &CanReport) -> String {
    let mut s = format!(
        "can bus ({}): {n} ESCs, {} transfers in {} frames",
        r.output, r.transfers, r.frames
    );
    if r.received > 0 || r.refused > 0 {
        s.push_str(&format!(
            "; {} frames from the controller, {} answers",
            r.received, r.answers
        ));
    }
    if r.refused > 0 {
        s.push_str(&format!(", {} SLCAN commands refused", r.refused));
    }
    if r.undelivered > 0 {
        s.push_str(&format!(
            "; {} frames not delivered (no reader, or the adapter's channel closed)",
            r.undelivered
        ));
    }
    s
}
