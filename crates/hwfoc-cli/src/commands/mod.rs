//! One module per subcommand: its options (a clap `Args` struct) and its `run`.

pub mod bridge;
pub mod can;
pub mod check;
pub mod completions;
pub mod decode;
pub mod man;
pub mod monitor;
pub mod plot;
pub mod record;
pub mod simulate;
pub mod summary;
pub mod web;
pub mod wireshark;
