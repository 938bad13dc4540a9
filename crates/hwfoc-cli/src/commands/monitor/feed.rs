//! Where the monitor's bytes come from: serial ports, or virtual ESCs running in this process.
//!
//! Either way they arrive as [`PortEvent`]s on one channel, together with the keys pressed
//! (from the dashboard's keyboard thread), so that the monitor waits on a single thing and
//! reacts to whichever comes first.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::thread::{self, JoinHandle};

use hwfoc::Settings;

use crate::commands::simulate::ModelArgs;
use crate::error::CliError;
use hwfoc_io::write::WriteError;
use hwfoc_ports::serial::{Baud, PortEvent, Readers};
use hwfoc_sim::{Sink, VirtualFleet};

/// What the monitor's loop receives.
#[derive(Debug)]
pub enum Msg {
    /// Something from a port or a virtual ESC.
    Port(PortEvent),
    /// Something from the terminal (dashboard only).
    Term(ratatui::crossterm::event::Event),
    /// A source stopped for good (the virtual ESCs failed).
    Failed(CliError),
}

/// The running source; dropping it stops it.
pub enum Feed {
    /// Serial ports, a reader thread each.
    Ports(Readers),
    /// Virtual ESCs in a thread.
    Simulated {
        /// Set to stop the thread.
        stop: Arc<AtomicBool>,
        /// The thread.
        thread: Option<JoinHandle<()>>,
    },
}

impl Drop for Feed {
    fn drop(&mut self) {
        if let Feed::Simulated { stop, thread } = self {
            stop.store(true, Ordering::Relaxed);
            if let Some(thread) = thread.take() {
                let _ = thread.join();
            }
        }
    }
}

impl Feed {
    /// Opens `ports` at `baud` (all of them, or an error naming the first that fails; at
    /// [`Baud::Auto`] each finds its rate); their reader threads send their events straight to
    /// `tx`.
    pub fn ports(ports: &[String], baud: Baud, tx: Sender<Msg>) -> Result<Feed, CliError> {
        let readers = Readers::start(ports, baud, tx, Msg::Port)?;
        Ok(Feed::Ports(readers))
    }

    /// Starts `n` virtual ESCs described by `model` in real time, in a thread of their own.
    pub fn simulated(
        model: &ModelArgs,
        n: usize,
        baud: u32,
        settings: &Settings,
        tx: Sender<Msg>,
    ) -> Result<Feed, CliError> {
        let fleet: VirtualFleet = model.fleet(n, baud, settings)?;
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let thread = thread::Builder::new()
            .name("virtual escs".into())
            .spawn(move || {
                let mut sink = ChannelSink { tx: tx.clone() };
                if let Err(e) = fleet.run_live(&mut sink, &flag)
                    && !flag.load(Ordering::Relaxed)
                {
                    let _ = tx.send(Msg::Failed(e.into()));
                }
            })
            .map_err(|e| CliError::Usage {
                option: "--sim".into(),
                message: format!("cannot start the virtual ESCs: {e}"),
            })?;
        Ok(Feed::Simulated {
            stop,
            thread: Some(thread),
        })
    }
}

/// Hands the virtual ESCs' bytes to the monitor as if a port had read them.
struct ChannelSink {
    tx: Sender<Msg>,
}

impl Sink for ChannelSink {
    fn write(&mut self, esc: usize, t_ns: u64, bytes: &[u8]) -> Result<bool, WriteError> {
        let event = PortEvent::Data {
            port: esc,
            t_ns,
            bytes: bytes.to_vec(),
        };
        // The monitor has gone: nothing left to deliver to, and the run is being stopped.
        Ok(self.tx.send(Msg::Port(event)).is_ok())
    }

    fn flush(&mut self) -> Result<(), WriteError> {
        Ok(())
    }
}
