//! Virtual Hobbywing DroneCAN ESCs (XRotor X6/X8/X9 and H-series "CAN" versions) on a
//! simulated CAN bus (`docs/HW5-AND-CAN.md`, "Hobbywing DroneCAN ESCs"): the same physical
//! model, throttle profiles and injected faults as the serial virtual ESCs, their transfers
//! made by the codec's encoders ([`hwfoc::dronecan::Message::frames`]).
//!
//! # What each ESC sends
//!
//! | message | default rate | priority | contents |
//! |---|---|---|---|
//! | `com.hobbywing.esc.StatusMsg1` (20050) | 50 Hz (code 5) | 16 | `rpm` mechanical (eRPM / pole pairs), `pwm` output throttle in 1000ths, `status` bit 14 = counter-clockwise (no other bit) |
//! | `com.hobbywing.esc.StatusMsg2` (20051) | 50 Hz (code 5) | 16 | bus voltage (0.1 V), input current (0.1 A, negative while braking), MOSFET temperature (degC) |
//! | `com.hobbywing.esc.StatusMsg3` (20052) | 10 Hz (code 7) | 16 | MOSFET, capacitor, motor (ambient + 0.8 of the MOSFETs' rise) temperatures, degC |
//! | `uavcan.protocol.NodeStatus` (341) | 1 Hz | 16 | uptime, health OK (WARNING while the model or an injected fault raises a status bit), mode OPERATIONAL |
//!
//! Each message has its own 5-bit transfer id counter per ESC (as have the ESC's GetEscID
//! answers), and starts at a random phase within its first interval (from the seed), not in
//! the first 5 ms ([`QUIET_START_NS`]: a controller's request at the start is answered first). The
//! rates are the simulator's choice (Hobbywing documents no default); `SetReportingFrequency`
//! changes them (codes 1..9 = 500, 250, 200, 100, 50, 20, 10, 1, 0 Hz). Priority 16 is
//! DroneCAN's "medium", a choice too.
//!
//! Faults: the status word's one known bit is the direction, so an injected fault shows only
//! through the model (a lost throttle signal stops the motor, an overheat raises the
//! temperatures), in NodeStatus's health, and in the self test. Link faults are not simulated
//! on the bus ([`SimError::CanLinkFaults`](crate::SimError::CanLinkFaults)).
//!
//! # Set up, or as from the factory
//!
//! Set up (the default): ESC `i` is node `10 + i` ([`FIRST_NODE`]), throttle channel `i + 1`,
//! clockwise for even `i` and counter-clockwise for odd (a multirotor's alternate), throttle
//! from CAN, LED green steady, 500 kbit/s. From the factory (`--factory`): every ESC node 1,
//! throttle channel 1, clockwise, 500 kbit/s ([`EscConfig::FACTORY`]); they all answer a
//! request to node 1, and all take a SetID addressed to it, as real ones would.
//!
//! # What the ESCs answer ([`CanBus::receive`])
//!
//! A broadcast `com.hobbywing.esc.GetEscID` of `[0]`: every ESC answers with a GetEscID
//! broadcast of `[node_id, throttle_channel]`. A service request whose destination is an ESC's
//! node: a response to the requester, with the request's priority and transfer id, 1 ms later
//! ([`ANSWER_NS`]), from the node that was asked:
//!
//! | service | the virtual ESC |
//! |---|---|
//! | SetID (210) | takes node 1..127 and channel 1..63 (else keeps its own), answers what it now has; sends as the new node from then on |
//! | SetBaud (211) | answers (empty), then runs at the new rate (codes 0..5 = 1 M .. 50 k): at another rate than the bus's it is neither heard nor hears |
//! | SetLED (212) | takes colour 0..7 and blink 0, 1, 2, 5; answers option, colour, blink |
//! | SetDirection (213) | 0 CW, 1 CCW (StatusMsg1's bit 14), 255 (or anything else) only asks; answers the direction |
//! | SetReportingFrequency (214) | `MSG_ID` a status message's data type id (20050..20052); option 1 writes a rate code 1..9; answers the rate code (9 for another `MSG_ID`) |
//! | SetThrottleSource (215) | 0 CAN, 1 PWM (the throttle is the profile either way); answers the source |
//! | SelfTest (216) | 1 (fail) while the motor turns or a fault is injected, else 0 |
//! | GetMaintenanceInformation (241) | minutes of rotation in all and since maintenance (before the run, drawn from the seed; plus the minutes the motor turned); option 1 clears the second |
//! | GetMajorConfig (242) | direction, throttle source, channel, LED blink (as `led_status`) and colour, StatusMsg1 and StatusMsg2 rate codes, angle 0 |
//!
//! SetAngle (217) is not answered.
//!
//! # Timing on the bus
//!
//! Every frame occupies the bus `67 + 8 * bytes` bit times ([`frame_bits`]) at 500 kbit/s;
//! a transfer due while the bus is busy waits (in the order transfers fell due). 16 ESCs at
//! the default rates load the bus about 40 %.
//!
//! | module | holds |
//! |---|---|
//! | `esc` | [`CanEsc`], [`EscConfig`], [`Stream`], the defaults |
//! | `bus` | [`CanBus`], [`Sent`] |
//! | `slcan` | the adapter's side of SLCAN ([`slcan::Adapter`]) |
//! | `run` | [`CanSession`]: a bus into a candump log, a pcapng recording or an SLCAN pty, with its ground truth and, in a log, a virtual controller asking for ids |

mod bus;
mod esc;
mod run;
pub mod slcan;

pub use bus::{ANSWER_NS, CanBus, MAX_CAN_ESCS, Sent, frame_bits};
pub use esc::{
    CanEsc, CanSetup, DEFAULT_LED, DEFAULT_RATES, EscConfig, FACTORY_BITRATE, FACTORY_NODE,
    FIRST_NODE, MAX_CHANNEL, NODE_STATUS_NS, Outgoing, PRIORITY, QUIET_START_NS, Stream,
    rate_interval_ns,
};
pub use run::{CanDestination, CanPlan, CanReport, CanSession, INTERFACE, truth_json};

#[cfg(test)]
mod tests;
