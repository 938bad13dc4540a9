//! Fault episodes: maximal runs of consecutive data frames of one ESC whose status word is not
//! zero, as the summary reports them and the plots shade them.

use hwfoc::Status;

/// One end of a fault episode: a data frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mark {
    /// Receive time, if the input has timing.
    pub t: Option<f64>,
    /// Index of the data frame among the ESC's data frames (0-based).
    pub frame: u64,
    /// Its packet number, where its protocol sends one.
    pub packet: Option<u32>,
}

/// A maximal run of consecutive data frames with a non-zero status word.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Episode {
    /// Its first frame.
    pub first: Mark,
    /// Its last frame.
    pub last: Mark,
    /// How many frames it lasted.
    pub frames: u64,
    /// Every status bit seen during the episode.
    pub bits: Status,
    /// Still going on at the end of the input.
    pub ongoing: bool,
}

impl Episode {
    /// When it was, from its first to its last faulty frame: `5.020 .. 5.270 s` on the
    /// source's clock, dates on a wall clock (`wall`), `frames 12 .. 17` without receive
    /// times. The one way the summary and the plot say it.
    pub fn when(&self, wall: bool) -> String {
        match (self.first.t, self.last.t) {
            (Some(a), Some(b)) if wall => {
                format!("{} .. {}", crate::time::iso8601(a), crate::time::iso8601(b))
            }
            (Some(a), Some(b)) => format!("{a:.3} .. {b:.3} s"),
            _ => format!("frames {} .. {}", self.first.frame, self.last.frame),
        }
    }

    /// Follows the fault episodes of one ESC through its data frames, in order: a frame with a
    /// non-zero status word starts the open episode `open` or extends it, a clean frame ends
    /// it. Returns the episode the frame ended, if any.
    #[inline]
    pub fn track(open: &mut Option<Episode>, mark: Mark, status: Status) -> Option<Episode> {
        if status.is_ok() {
            return open.take();
        }
        match open {
            Some(e) => {
                e.last = mark;
                e.frames += 1;
                e.bits = Status(e.bits.0 | status.0);
            }
            None => {
                *open = Some(Episode {
                    first: mark,
                    last: mark,
                    frames: 1,
                    bits: status,
                    ongoing: false,
                })
            }
        }
        None
    }
}
