//! `hwfoc bridge`: telemetry from any input to the protocols flight controllers and ground
//! stations read (DataLink V2 frames, MAVLink, DroneCAN), several at once.
//!
//! The outputs are `hwfoc_bridge` [`Output`]s behind one [`Fanout`]; this module opens them
//! from the options, feeds them from live ports or virtual ESCs (as the monitor reads them) or
//! from recordings replayed in real time, reports their failures as they happen (without
//! stopping) and their counters at the end.

mod report;

use std::sync::atomic::Ordering;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::{Duration, Instant};

use clap::Args;
use hwfoc_bridge::Output;
use hwfoc_bridge::datalink::{DatalinkOutput, Pacing};
use hwfoc_bridge::dronecan::{self, DronecanOptions, DronecanOutput, SlcanTarget};
use hwfoc_bridge::fanout::Fanout;
use hwfoc_bridge::mavlink::{self, MavlinkOptions, MavlinkOutput, MavlinkTarget};
use hwfoc_bridge::replay::{POLL, Replay, ReplayError};
use hwfoc_io::Notice;
use hwfoc_io::OpenInput;
use hwfoc_io::PortStreams;
use hwfoc_io::SettingsMap;
use hwfoc_io::Sources;
use hwfoc_ports::serial::{self, PortEvent};

use crate::args::{ProtocolArgs, SettingsArgs, seconds};
use crate::commands::monitor::feed::{Feed, Msg};
use crate::commands::simulate::ModelArgs;
use crate::config::Config;
use crate::error::CliError;

use report::Errors;

/// The most virtual ESCs `--sim` runs.
const MAX_SIM: u16 = 64;

const EXAMPLES: &str = "\
Examples:
  hwfoc bridge --sim 4 --mavlink udp:127.0.0.1:14550     # four virtual ESCs to a ground station
  hwfoc bridge /dev/ttyUSB0 /dev/ttyUSB1 --datalink /dev/ttyAMA0
  hwfoc bridge flight.pcapng --mavlink udp:192.168.1.20:14550 --dronecan slcan:/dev/ttyACM0
  hwfoc bridge flight.pcapng --mavlink file:flight.tlog   # a telemetry log, the flight's times";

/// Arguments of `hwfoc bridge`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct BridgeArgs {
    /// Serial ports (read live, one ESC each, or eight from a DataLink hub) or recordings and
    /// other inputs (replayed in real time).
    #[arg(
        value_name = "PORT|FILE",
        required_unless_present = "sim",
        conflicts_with = "sim"
    )]
    inputs: Vec<String>,
    /// Run N virtual ESCs instead of reading inputs (the Throttle, Model and Faults options of
    /// `hwfoc simulate` shape them).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=MAX_SIM as i64))]
    sim: Option<u16>,
    /// Baud rate of the input ports (8N1) [default: that of --protocol, else found from the
    /// bytes: 19200 and 115200 tried in turn].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    baud: Option<u32>,
    #[command(flatten)]
    protocol: ProtocolArgs,
    /// Read the recordings given as one: their ports go on from file to file by name. Without
    /// it, only the files of one `hwfoc record` run (rotated files: they carry its recording
    /// id) are one recording; every other file is ESCs of its own, however its ports are
    /// named (port names such as /dev/ttyUSB0 are the same on every drone). Give it for the
    /// parts of one recording that another program wrote or cut.
    #[arg(long)]
    join: bool,

    /// DataLink V2 frames (115200 baud) of ESCs 0 to 7 on this serial port: hwfoc as the
    /// DataLink box a flight controller reads.
    #[arg(long, value_name = "PORT", help_heading = "Outputs")]
    datalink: Option<String>,
    /// Milliseconds from one DataLink frame to the next (the ESCs' own period; an ESC's next
    /// frame arriving sooner is sent sooner).
    #[arg(long, value_name = "MS", default_value_t = 50, help_heading = "Outputs",
          value_parser = clap::value_parser!(u64).range(20..=1000))]
    datalink_period: u64,

    /// MAVLink 2 to a ground station or flight controller: `udp:HOST:PORT` (`udp` alone is
    /// 127.0.0.1:14550, where ground stations listen) or `serial:PORT[:BAUD]`; or `file:PATH`, a
    /// telemetry log (.tlog, as Mission Planner writes and reads them). HEARTBEAT,
    /// ESC_TELEMETRY_1_TO_4.. (Mission Planner), ESC_STATUS and ESC_INFO (QGroundControl, PX4).
    /// Repeat for several destinations.
    #[arg(long, value_name = "SPEC", help_heading = "Outputs")]
    mavlink: Vec<String>,
    /// MAVLink system id of the messages (1: the vehicle's, as ground stations expect).
    #[arg(long, value_name = "N", default_value_t = 1, help_heading = "Outputs",
          value_parser = clap::value_parser!(u8).range(1..=255))]
    mavlink_system: u8,
    /// A `--mavlink file:PATH` may replace an existing file (never one of the inputs).
    #[arg(long, help_heading = "Outputs")]
    overwrite: bool,
    /// MAVLink component id: 158 (peripheral) beside a flight controller; 1 (autopilot) on a
    /// bench without one, so that the ground station takes hwfoc for the vehicle.
    #[arg(long, value_name = "N", default_value_t = mavlink::MAV_COMP_ID_PERIPHERAL,
          help_heading = "Outputs", value_parser = clap::value_parser!(u8).range(1..=255))]
    mavlink_component: u8,

    /// A DroneCAN node on an SLCAN adapter, `slcan:PORT[:BITRATE]` (default 1000000 bit/s):
    /// uavcan.equipment.esc.Status and StatusExtended for each ESC, and NodeStatus.
    #[arg(long, value_name = "SPEC", help_heading = "Outputs")]
    dronecan: Option<String>,
    /// DroneCAN node id (1 to 127).
    #[arg(long, value_name = "N", default_value_t = dronecan::DEFAULT_NODE_ID,
          help_heading = "Outputs", value_parser = clap::value_parser!(u8).range(1..=127))]
    dronecan_node: u8,
    /// Baud rate of the SLCAN adapter's serial port (USB adapters ignore it).
    #[arg(long, value_name = "N", default_value_t = dronecan::DEFAULT_BAUD,
          help_heading = "Outputs", value_parser = clap::value_parser!(u32).range(1..))]
    dronecan_baud: u32,

    /// Replay recordings in real time even when every output is a file: a `--mavlink file:`
    /// telemetry log is otherwise written as fast as it can be, with the recording's own times.
    #[arg(long)]
    realtime: bool,
    /// How long to run, in seconds (default: until Ctrl-C, or the end of the recordings).
    #[arg(long, value_name = "S", value_parser = seconds)]
    duration: Option<f64>,
    /// No messages of output failures while running (they are still counted in the report).
    #[arg(long, short)]
    quiet: bool,

    #[command(flatten)]
    settings: SettingsArgs,
    #[command(flatten)]
    model: ModelArgs,
}

/// Runs `hwfoc bridge`.
pub fn run(args: &BridgeArgs) -> Result<(), CliError> {
    if args.sim.is_none() && !args.model.is_default() {
        return Err(CliError::Usage {
            option: "bridge".into(),
            message: "the Throttle, Model and Faults options drive virtual ESCs: add --sim N"
                .into(),
        });
    }
    // Every ESC's settings, from the configuration file (per port, per ESC) and the flags.
    let (config, settings) = args.settings.settings_map()?;
    let outputs = open_outputs(args, &config)?;
    let mut fanout = Fanout::new(outputs);
    let mut errors = Errors::new(args.quiet);
    let started = Instant::now();
    let deadline = args.duration.map(|s| started + Duration::from_secs_f64(s));

    let (ports, files): (Vec<&String>, Vec<&String>) =
        args.inputs.iter().partition(|spec| serial::is_port(spec));
    if let (Some(port), Some(file)) = (ports.first(), files.first()) {
        return Err(CliError::MixedInputs {
            port: port.to_string(),
            file: file.to_string(),
        });
    }
    let protocol = args.protocol.protocol;
    let baud = args.protocol.baud(args.baud);
    let result = if ports.is_empty() && args.sim.is_none() {
        replay(
            &files,
            settings,
            (protocol, args.join),
            (deadline, !args.realtime && only_files(args)),
            &mut fanout,
            &mut errors,
        )
    } else {
        let (tx, rx) = mpsc::channel();
        let (names, feed) = match args.sim {
            Some(n) => {
                let feed = Feed::simulated(
                    &args.model,
                    usize::from(n),
                    baud.initial(),
                    settings.default_settings(),
                    tx,
                )?;
                ((0..n).map(|i| format!("sim:esc{i}")).collect(), feed)
            }
            None => {
                let names: Vec<String> = ports.iter().map(|p| p.to_string()).collect();
                args.protocol
                    .check_ports(names.iter().map(String::as_str))?;
                let feed = Feed::ports(&names, baud, tx)?;
                (names, feed)
            }
        };
        let mut streams = PortStreams::with_map(baud.initial(), names.clone(), settings);
        if let Some(protocol) = protocol {
            streams.force_protocol(protocol);
        }
        if baud == hwfoc_ports::serial::Baud::Auto && args.sim.is_none() {
            streams.auto_baud();
        }
        let per_byte_ns = hwfoc::wire::byte_ns(baud.initial());
        let result = live(
            &rx,
            &names,
            &mut streams,
            per_byte_ns,
            deadline,
            &mut fanout,
            &mut errors,
        );
        drop(feed);
        result
    };
    // What is still waiting goes out.
    fanout.poll(Instant::now(), |e| errors.report(&e));
    report::print(&fanout, started.elapsed());
    result?;
    // ESCs an output could not carry: output lost, said in the report and in the exit status.
    match report::not_carried(&fanout) {
        Some(e) => Err(CliError::Output(e)),
        None => Ok(()),
    }
}

/// Opens every output named; at least one.
fn open_outputs(args: &BridgeArgs, config: &Config) -> Result<Vec<Box<dyn Output>>, CliError> {
    // What the bridge reads, which no output may be: its inputs and the configuration file.
    let read: Vec<std::path::PathBuf> = args
        .inputs
        .iter()
        .map(std::path::PathBuf::from)
        .chain(crate::safety::config_read(config))
        .collect();
    let mut outputs: Vec<Box<dyn Output>> = Vec::new();
    if let Some(port) = &args.datalink {
        let pacing = Pacing {
            period: Duration::from_millis(args.datalink_period),
            ..Pacing::default()
        };
        outputs.push(Box::new(
            DatalinkOutput::open(port, pacing).map_err(CliError::Output)?,
        ));
    }
    for spec in &args.mavlink {
        let target = MavlinkTarget::parse(spec).map_err(CliError::Output)?;
        if let MavlinkTarget::File(path) = &target {
            crate::safety::refuse_input(path, read.iter().map(std::path::PathBuf::as_path))?;
        }
        let options = MavlinkOptions {
            system_id: args.mavlink_system,
            component_id: args.mavlink_component,
            overwrite: args.overwrite,
            ..MavlinkOptions::default()
        };
        outputs.push(Box::new(
            MavlinkOutput::open(target, options).map_err(CliError::Output)?,
        ));
    }
    if let Some(spec) = &args.dronecan {
        let target = SlcanTarget::parse(spec).map_err(CliError::Output)?;
        let options = DronecanOptions {
            node_id: args.dronecan_node,
            baud: args.dronecan_baud,
        };
        outputs.push(Box::new(
            DronecanOutput::open(target, options).map_err(CliError::Output)?,
        ));
    }
    if outputs.is_empty() {
        return Err(CliError::Usage {
            option: "bridge".into(),
            message: "name an output: --datalink PORT, --mavlink udp:127.0.0.1:14550 or \
                      --dronecan slcan:PORT"
                .into(),
        });
    }
    Ok(outputs)
}

/// Live ports or virtual ESCs: their events through the monitor's decoding path.
fn live(
    rx: &mpsc::Receiver<Msg>,
    names: &[String],
    streams: &mut PortStreams,
    per_byte_ns: f64,
    deadline: Option<Instant>,
    fanout: &mut Fanout,
    errors: &mut Errors,
) -> Result<(), CliError> {
    let stop = crate::stop::interrupted();
    let clock = hwfoc_ports::clock::ReceiveClock::new();
    while !stop.load(Ordering::Relaxed) && deadline.is_none_or(|d| Instant::now() < d) {
        let mut msg = match rx.recv_timeout(POLL) {
            Ok(msg) => Some(msg),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => break,
        };
        // Everything that has arrived, then the outputs.
        while let Some(m) = msg {
            match m {
                Msg::Port(event) => take(&event, names, streams, per_byte_ns, &clock, fanout),
                Msg::Failed(e) => return Err(e),
                Msg::Term(_) => {}
            }
            msg = rx.try_recv().ok();
        }
        fanout.poll(Instant::now(), |e| errors.report(&e));
    }
    Ok(())
}

/// Decodes a port's event into the outputs.
fn take(
    event: &PortEvent,
    names: &[String],
    streams: &mut PortStreams,
    per_byte_ns: f64,
    clock: &hwfoc_ports::clock::ReceiveClock,
    fanout: &mut Fanout,
) {
    match event {
        PortEvent::Data { port, t_ns, bytes } => {
            // The read that completed these bytes returned when the last of them arrived.
            let per_byte_ns = streams
                .baud(*port)
                .map_or(per_byte_ns, hwfoc::wire::byte_ns);
            let last_ns = *t_ns as f64 + per_byte_ns * bytes.len().saturating_sub(1) as f64;
            let ago_ns = (clock.now_ns() as f64 - last_ns).max(0.0);
            let now = Instant::now();
            fanout.arrived(
                now.checked_sub(Duration::from_nanos(ago_ns as u64))
                    .unwrap_or(now),
            );
            streams.feed(event, fanout);
        }
        PortEvent::Searching { .. } => {
            streams.feed(event, fanout);
        }
        PortEvent::Lost { .. } | PortEvent::Back { .. } | PortEvent::Found { .. } => {
            // A rate found sets the port's byte time.
            streams.feed(event, fanout);
            if let Some(notice) = Notice::of_port_event(event, names) {
                eprintln!("{}", notice.line());
            }
        }
    }
}

/// Recordings and other inputs, replayed in real time (reading `protocol` only when given, the
/// recordings joined as one with `join`).
/// Whether every output is a file (`--mavlink file:`), which a replay may write as fast as it
/// can: the DataLink and DroneCAN outputs are serial ports, paced.
fn only_files(args: &BridgeArgs) -> bool {
    args.datalink.is_none()
        && args.dronecan.is_none()
        && !args.mavlink.is_empty()
        && args
            .mavlink
            .iter()
            .all(|spec| matches!(MavlinkTarget::parse(spec), Ok(MavlinkTarget::File(_))))
}

fn replay(
    files: &[&String],
    settings: SettingsMap,
    (protocol, join): (Option<hwfoc::Protocol>, bool),
    (deadline, fast): (Option<Instant>, bool),
    fanout: &mut Fanout,
    errors: &mut Errors,
) -> Result<(), CliError> {
    let inputs = files
        .iter()
        .map(|f| hwfoc_io::Input::open(f))
        .collect::<Result<Vec<_>, _>>()?;
    let mut sources = Sources::new(inputs, settings);
    if let Some(protocol) = protocol {
        sources.force_protocol(protocol);
    }
    if join {
        sources.join_recordings();
    }
    let stop = crate::stop::interrupted();
    // The deadline stops the replay as Ctrl-C would.
    let timer = deadline.map(|d| {
        let stop = std::sync::Arc::clone(&stop);
        std::thread::spawn(move || {
            while Instant::now() < d && !stop.load(Ordering::Relaxed) {
                std::thread::sleep(POLL);
            }
            stop.store(true, Ordering::Relaxed);
        })
    });
    let mut replay = Replay::new(fanout, &stop, |e| errors.report(&e));
    if fast {
        replay = replay.as_fast_as_possible();
    }
    let result = sources.run(&mut replay);
    stop.store(true, Ordering::Relaxed);
    if let Some(timer) = timer {
        let _ = timer.join();
    }
    match result {
        Ok(()) | Err(ReplayError::Stopped) => Ok(()),
        Err(ReplayError::Input(e)) => Err(e.into()),
    }
}
