//! `hwfoc can`: set up Hobbywing's DroneCAN ESCs (XRotor X6/X8/X9 and H-series "CAN"
//! versions) in the open, as the DataLink's CAN tab does: list them (`list`), give one a node
//! id and throttle channel (`set-id`), change its direction, throttle source, LED, reporting
//! rates or bit rate (`set`), run its self test (`self-test`). The protocol is
//! [`hwfoc_can_setup`]'s [`Client`]; this module holds the options, the confirmation and
//! the presentation (`list`: the table and the JSON; `change`: the other subcommands).

mod change;
mod list;

use std::sync::Arc;
use std::time::Duration;

use clap::{Args, Subcommand};
use hwfoc_can_setup::Client;
use hwfoc_ports::can::CanBus;

use crate::error::CliError;

const AFTER_HELP: &str = "Examples:
  hwfoc can list slcan:/dev/ttyACM0              # every ESC: node, channel, settings, counters
  hwfoc can set-id slcan:/dev/ttyACM0 --node 1 --to 11 --channel 1
  hwfoc can set slcan:/dev/ttyACM0 --node 11 --direction ccw --led red,2
  hwfoc can self-test slcan:/dev/ttyACM0 --node 11

hwfoc listens 1.1 s before it sends anything. Nothing is changed while any node reports its
motor turning, and nothing that can turn a motor (direction, throttle source, node id, bit
rate) is sent to an ESC whose rpm and pwm (StatusMsg1) were not heard at rest just before;
every change is shown and confirmed (--yes for scripts), then read back from the ESC.";

/// `hwfoc can`'s options.
#[derive(Debug, Args)]
#[command(after_help = AFTER_HELP)]
pub struct CanArgs {
    #[command(subcommand)]
    command: CanCommand,
}

#[derive(Debug, Subcommand)]
enum CanCommand {
    /// List the ESCs on the bus: node id, throttle channel, direction, throttle source, LED,
    /// message rates, maintenance counters, what they report; and ESCs sharing a node id.
    List(list::ListArgs),
    /// Give one ESC a node id and throttle channel (SetID), then read it back.
    SetId(change::SetIdArgs),
    /// Change an ESC's direction, throttle source, LED, reporting rates or bit rate, then read
    /// them back.
    Set(change::SetArgs),
    /// Run an ESC's self test and say whether it passed.
    SelfTest(change::SelfTestArgs),
}

/// The bus and how hwfoc speaks on it: every subcommand's.
#[derive(Debug, Args)]
struct BusArgs {
    /// The CAN bus: `slcan:PORT[:BITRATE]` (an SLCAN adapter such as a CANable; 500k, the ESCs'
    /// factory rate, unless given) or can:IFACE (a SocketCAN interface, Linux).
    #[arg(value_name = "BUS")]
    bus: String,
    /// The node id hwfoc sends from.
    #[arg(long, value_name = "N", default_value_t = hwfoc_ports::can::DEFAULT_SOURCE_NODE,
          value_parser = clap::value_parser!(u8).range(1..=127))]
    source: u8,
    /// How long to wait for each answer of an ESC, seconds.
    #[arg(long, value_name = "S", default_value = "1", value_parser = crate::args::seconds)]
    timeout: f64,
}

impl BusArgs {
    /// The bus opened, as a client stopped by Ctrl-C, after listening so that every node is
    /// heard ([`Client::listen_first`]); refused if another node has `--source`'s id.
    fn open(&self) -> Result<Client, CliError> {
        let bus = CanBus::open(&self.bus, false)?;
        let mut client = Client::new(bus, self.source, Arc::clone(&crate::stop::interrupted()));
        client.listen_first()?;
        if client.heard().node(self.source).is_some() {
            return Err(CliError::Usage {
                option: format!("--source {}", self.source),
                message: format!(
                    "node {} is on the bus {}: hwfoc would send as it; choose a free node id",
                    self.source, self.bus
                ),
            });
        }
        Ok(client)
    }

    /// The bit rate the bus was opened at, where known (an `slcan:` bus's).
    fn bitrate(&self) -> Option<u32> {
        match hwfoc_ports::can::CanSpec::parse(&self.bus).ok()? {
            hwfoc_ports::can::CanSpec::Slcan { bitrate, .. } => Some(bitrate),
            hwfoc_ports::can::CanSpec::SocketCan { .. } => None,
        }
    }

    fn timeout(&self) -> Duration {
        Duration::from_secs_f64(self.timeout)
    }
}

/// Runs the subcommand.
pub fn run(args: &CanArgs) -> Result<(), CliError> {
    match &args.command {
        CanCommand::List(a) => list::run(a),
        CanCommand::SetId(a) => change::set_id(a),
        CanCommand::Set(a) => change::set(a),
        CanCommand::SelfTest(a) => change::self_test(a),
    }
}
