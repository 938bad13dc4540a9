//! `hwfoc can set-id`, `set` and `self-test`: the safety check, the confirmation, the
//! requests and their read-back.

use std::io::{BufRead, IsTerminal, Write};

use clap::Args;
use hwfoc::dronecan::{Message, SelfTestRequest};
use hwfoc_can_setup::{
    Change, Client, Direction, Led, SetupError, ThrottleSource, baud_code, parse_rate,
};

use super::BusArgs;
use crate::error::CliError;

/// `hwfoc can set-id`'s options.
#[derive(Debug, Args)]
pub struct SetIdArgs {
    #[command(flatten)]
    bus: BusArgs,
    /// The ESC's node id now (1 from the factory).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..=127))]
    node: u8,
    /// Its new node id.
    #[arg(long, value_name = "NEW", value_parser = clap::value_parser!(u8).range(1..=127))]
    to: u8,
    /// Its throttle channel (1-based: the motor's output of the flight controller).
    #[arg(long, value_name = "C", value_parser = clap::value_parser!(u8).range(1..=63))]
    channel: u8,
    /// Make the change without asking.
    #[arg(long)]
    yes: bool,
}

/// `hwfoc can set`'s options.
#[derive(Debug, Args)]
#[command(group = clap::ArgGroup::new("changes").required(true).multiple(true))]
pub struct SetArgs {
    #[command(flatten)]
    bus: BusArgs,
    /// The ESC's node id.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..=127))]
    node: u8,
    /// Motor direction: cw or ccw (SetDirection).
    #[arg(long, value_name = "cw|ccw", group = "changes")]
    direction: Option<Direction>,
    /// Where the throttle comes from: can or pwm (SetThrottleSource).
    #[arg(long, value_name = "can|pwm", group = "changes")]
    throttle_source: Option<ThrottleSource>,
    /// LED: `COLOR[,BLINK][,save]`; COLOR off, blue, green, cyan, red, magenta, yellow, white;
    /// BLINK 0 (steady), 1, 2 or 5 Hz; save to keep it (SetLED).
    #[arg(long, value_name = "COLOR[,BLINK][,save]", group = "changes")]
    led: Option<Led>,
    /// A status message's rate: msg1, msg2 or msg3 = 500, 250, 200, 100, 50, 20, 10, 1 or 0
    /// Hz (SetReportingFrequency; repeatable).
    #[arg(long, value_name = "MSG=HZ", value_parser = parse_rate, group = "changes")]
    rate: Vec<Change>,
    /// The ESC's CAN bit rate: 1000000, 500000, 250000, 200000, 100000 or 50000 (SetBaud;
    /// made last: the ESC is then heard only at that rate).
    #[arg(long, value_name = "B", value_parser = bitrate, group = "changes")]
    bitrate: Option<u32>,
    /// Make the changes without asking.
    #[arg(long)]
    yes: bool,
}

/// `hwfoc can self-test`'s options.
#[derive(Debug, Args)]
pub struct SelfTestArgs {
    #[command(flatten)]
    bus: BusArgs,
    /// The ESC's node id.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..=127))]
    node: u8,
}

fn bitrate(text: &str) -> Result<u32, String> {
    text.parse::<u32>()
        .ok()
        .filter(|&b| baud_code(b).is_some())
        .ok_or_else(|| {
            format!("{text:?}: one of 1000000, 500000, 250000, 200000, 100000, 50000 (bit/s)")
        })
}

/// Runs `hwfoc can set-id`.
pub fn set_id(args: &SetIdArgs) -> Result<(), CliError> {
    can_confirm(args.yes)?;
    let mut client = args.bus.open()?;
    if args.to != args.node && client.heard().node(args.to).is_some() {
        return Err(CliError::Usage {
            option: format!("--to {}", args.to),
            message: format!(
                "node {} is already on {}: choose a free id (`hwfoc can list`)",
                args.to, args.bus.bus
            ),
        });
    }
    client.check_at_rest(args.node, true)?;
    client.check_alone(args.node)?;
    let was = match client
        .heard()
        .node(args.node)
        .and_then(|n| n.channels.last())
    {
        Some(c) => format!("node id {}, throttle channel {c}", args.node),
        None => format!("node id {}", args.node),
    };
    let change = Change::NodeId {
        node_id: args.to,
        channel: args.channel,
    };
    confirm(
        args.yes,
        &[format!("node {}: {was} -> {change}", args.node)],
    )?;
    make(&mut client, &args.bus, args.node, &change)
}

/// Runs `hwfoc can set`.
pub fn set(args: &SetArgs) -> Result<(), CliError> {
    can_confirm(args.yes)?;
    let mut changes: Vec<Change> = Vec::new();
    changes.extend(args.direction.map(Change::Direction));
    changes.extend(args.throttle_source.map(Change::ThrottleSource));
    changes.extend(args.led.map(Change::Led));
    changes.extend(args.rate.iter().copied());
    changes.extend(args.bitrate.map(Change::Bitrate));
    let mut client = args.bus.open()?;
    client.check_at_rest(args.node, changes.iter().any(Change::affects_motor))?;
    client.check_alone(args.node)?;
    let timeout = args.bus.timeout();
    let mut plan = Vec::new();
    for c in &changes {
        let was = match client.read(args.node, c, timeout)? {
            Some(was) => was.to_string(),
            None => match args.bus.bitrate() {
                Some(b) => format!("bit rate {b} bit/s"),
                None => "bit rate of the bus".to_string(),
            },
        };
        plan.push(format!("node {}: {was} -> {c}", args.node));
    }
    confirm(args.yes, &plan)?;
    // Each change is said as it is made: a later one that fails leaves them listed.
    for c in &changes {
        make(&mut client, &args.bus, args.node, c)?;
    }
    Ok(())
}

/// Checks again that every motor is at rest, makes `change` and says what the ESC now says
/// (an error if it says otherwise: nothing more is sent).
fn make(client: &mut Client, bus: &BusArgs, node: u8, change: &Change) -> Result<(), CliError> {
    client.check_at_rest(node, change.affects_motor())?;
    let made = client.change(node, change, bus.timeout())?;
    if let Some(late) = made.late {
        eprintln!("hwfoc: {late}");
    }
    match (made.said, change) {
        (Some(said), _) => println!("node {node} now says: {said}"),
        (None, Change::Bitrate(b)) => println!(
            "node {node} answered: {change}; it is now heard only at that rate (open the bus at \
             it: slcan:PORT:{b})"
        ),
        (None, _) => {}
    }
    if let Change::Led(Led { save: true, .. }) = change {
        println!("node {node}: whether the LED was saved cannot be read back");
    }
    Ok(())
}

/// Runs `hwfoc can self-test`.
pub fn self_test(args: &SelfTestArgs) -> Result<(), CliError> {
    let mut client = args.bus.open()?;
    client.check_at_rest(args.node, true)?;
    client.check_alone(args.node)?;
    client.check_at_rest(args.node, true)?;
    let answer = client.call(
        args.node,
        Message::from(SelfTestRequest {}),
        args.bus.timeout(),
    )?;
    match answer {
        Message::SelfTestResponse(r) if r.status == 0 => {
            println!("node {}: self test passed", args.node);
            Ok(())
        }
        _ => Err(SetupError::SelfTestFailed {
            bus: client.bus().to_string(),
            node: args.node,
        }
        .into()),
    }
}

/// Refuses before anything is sent on the bus when the change could not be confirmed: no
/// terminal and no `--yes`.
fn can_confirm(yes: bool) -> Result<(), CliError> {
    if !yes && !std::io::stdin().is_terminal() {
        return Err(CliError::Usage {
            option: "--yes".to_string(),
            message: "no terminal to confirm the change on: pass --yes to make it".to_string(),
        });
    }
    Ok(())
}

/// Shows the plan and asks for a yes on the terminal; `--yes` skips the question; without a
/// terminal and without `--yes`, refuses ([`can_confirm`], also called before the bus is
/// opened).
fn confirm(yes: bool, plan: &[String]) -> Result<(), CliError> {
    can_confirm(yes)?;
    let stdin = std::io::stdin();
    let mut err = std::io::stderr().lock();
    for line in plan {
        let _ = writeln!(err, "{line}");
    }
    if yes {
        return Ok(());
    }
    let _ = write!(err, "Make the change? [y/N] ");
    let _ = err.flush();
    let mut answer = String::new();
    let _ = stdin.lock().read_line(&mut answer);
    if matches!(answer.trim().to_ascii_lowercase().as_str(), "y" | "yes") {
        Ok(())
    } else {
        Err(CliError::Declined)
    }
}
