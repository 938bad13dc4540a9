//! The seam between reading telemetry and doing something with it, as `Sink` is in ripgrep.
//!
//! [`crate::Sources::run`] (inputs read to their end) and
//! [`crate::PortStreams::feed`] (live port events) hand every frame to a [`Handler`].
//! A front end (a command, a bridge, a binding) implements [`Handler::record`] and
//! [`Handler::info`]: it sees records in physical units, the same whatever protocol the bytes
//! were in, never the codec's frames. The library's own handlers (the writers, the summary)
//! take the frames through [`Handler::frame`], as the protocol-neutral [`AnyFrame`] read through
//! [`hwfoc::Telemetry`], to convert a block at a time on their own threads or to keep raw
//! integers for exact means; none of them names a protocol's frame type.

use std::any::Any;

use hwfoc::Settings;
use hwfoc::foc::DataFrame;
use hwfoc::telemetry::{AnyFrame, Data, Info};

use crate::input::InputError;
use crate::record::Record;

/// What is done with the frames of a run of inputs or of live ports.
///
/// Its error type carries the handler's own failures (an output that cannot be written) and
/// the input errors met while reading, so that a front end sees one error type.
pub trait Handler {
    /// The handler's error: its own, or an input's (hence `From<InputError>`).
    type Error: From<InputError>;

    /// A data frame, as the record every output shows.
    #[inline]
    fn record(&mut self, record: &Record) {
        let _ = record;
    }

    /// A device-information frame of ESC `esc`, with the receive time of its first byte where
    /// the input has one.
    #[inline]
    fn info(&mut self, esc: u8, t: Option<f64>, info: &Info) {
        let _ = (esc, t, info);
    }

    /// A frame of ESC `esc`, of any protocol, with the receive time of its first byte where the
    /// input has one. The default converts a data frame under `settings` and hands it to
    /// [`Handler::record`], and a device-information frame to [`Handler::info`].
    #[inline]
    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &AnyFrame, settings: &Settings) {
        match frame {
            AnyFrame::Data(f) => self.record(&Record::new(t, esc, f, settings)),
            AnyFrame::Info(info) => self.info(esc, t, info),
        }
    }

    /// Whether the handler takes a raw input's data frames a run at a time
    /// ([`Handler::untimed_data`]), its regular files read ahead ([`crate::Input::read_ahead`]):
    /// for a handler whose work for a frame is small beside the decoder's (the summary). A
    /// handler that does more (the writers, on threads of their own) takes each frame in the
    /// decoder's loop, as by default.
    const TAKES_RUNS: bool = false;

    /// HW-FOC data frames of ESC `esc`'s own wire, one after another, without receive times
    /// (a raw input's), for a handler that [`takes runs`](Handler::TAKES_RUNS): what handing
    /// each to [`Handler::frame`] in turn (as [`Data::HwFoc`]) does, which the default does. A
    /// handler that gathers statistics takes them in a loop of its own. (The bulk path of the
    /// format of nearly every large file: its frames as the codec's HW-FOC type, whose readings
    /// are known at compile time and which is half the size of a [`Data`]; frames of every
    /// other format come through [`Handler::frame`].)
    #[inline]
    fn untimed_data(&mut self, esc: u8, frames: &[DataFrame], settings: &Settings) {
        for f in frames {
            self.frame(esc, None, &AnyFrame::Data(Data::HwFoc(*f)), settings);
        }
    }

    /// The end of a batch of bytes; `live` when it was small, as from a serial port (what it
    /// produced should be passed on at once). An error stops the run.
    fn end_batch(&mut self, live: bool) -> Result<(), Self::Error> {
        let _ = live;
        Ok(())
    }

    /// A part of this handler with nothing taken yet, to take on a thread of its own the frames
    /// of the later half of a large raw file while this handler takes those of the earlier
    /// half ([`crate::Sources`] reads such a file in two halves at once, the two decoders
    /// joined where they meet); [`Handler::join`] takes back what it gathered. `None`, the
    /// default, for a handler that must take every frame itself, in order (every writer: its
    /// output is in the frames' order).
    fn fork(&self) -> Option<Box<dyn LaterPart>> {
        None
    }

    /// Takes what `later`, a part made by [`Handler::fork`] (as [`LaterPart::into_any`] gives
    /// it), gathered of the frames that came right after every frame this handler has taken:
    /// afterwards the handler is as if it had taken them all itself, in order.
    fn join(&mut self, later: Box<dyn Any + Send>) {
        let _ = later;
    }
}

/// What a [`Handler`] forks ([`Handler::fork`]): it takes the frames of the later half of a raw
/// input (which have no receive times) on a thread of its own.
pub trait LaterPart: Send {
    /// A frame of ESC `esc`, as [`Handler::frame`] takes it (no receive time).
    fn frame(&mut self, esc: u8, frame: &AnyFrame, settings: &Settings);

    /// Data frames of ESC `esc`, as [`Handler::untimed_data`] takes them.
    fn untimed_data(&mut self, esc: u8, frames: &[DataFrame], settings: &Settings);

    /// The part, for its handler's [`Handler::join`].
    fn into_any(self: Box<Self>) -> Box<dyn Any + Send>;
}

/// No handler: the frames are decoded (for their link statistics) and dropped.
impl Handler for () {
    type Error = InputError;

    #[inline]
    fn frame(&mut self, _: u8, _: Option<f64>, _: &AnyFrame, _: &Settings) {}
}

/// Hands every frame to two handlers, each taking it its own way (as decoded, or as a record):
/// `hwfoc summary --plot` summarises and plots in one reading of the inputs. Its error is the
/// second handler's, which must take in the first's.
pub struct Both<'a, A, B>(pub &'a mut A, pub &'a mut B);

impl<A: Handler, B: Handler> Handler for Both<'_, A, B>
where
    B::Error: From<A::Error>,
{
    type Error = B::Error;

    const TAKES_RUNS: bool = A::TAKES_RUNS && B::TAKES_RUNS;

    #[inline]
    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &AnyFrame, settings: &Settings) {
        self.0.frame(esc, t, frame, settings);
        self.1.frame(esc, t, frame, settings);
    }

    #[inline]
    fn untimed_data(&mut self, esc: u8, frames: &[DataFrame], settings: &Settings) {
        self.0.untimed_data(esc, frames, settings);
        self.1.untimed_data(esc, frames, settings);
    }

    fn end_batch(&mut self, live: bool) -> Result<(), B::Error> {
        self.0.end_batch(live)?;
        self.1.end_batch(live)
    }
}
