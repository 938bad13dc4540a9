//! Bridges: hwfoc's telemetry written in the protocols that flight controllers and ground
//! stations already read.
//!
//! Every bridge is an [`Output`]: it is handed each ESC's frames as they are decoded
//! ([`Update`]: the raw frame, the record in physical units, and when its bytes arrived) and
//! asked regularly to send what is due ([`Output::poll`]). An output never stops the bridge: a
//! failure to send is an [`OutputError`] that the front end reports and counts, and the output
//! goes on with the next message (reopening its port where it has one).

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod datalink;
pub mod dronecan;
pub mod fanout;
pub mod hub_record;
pub mod latency;
pub mod mavlink;
pub mod output;
pub mod port;
pub mod replay;

pub use latency::Latency;
pub use output::{Output, OutputError, OutputStats, SILENT_AFTER, Update};
