//! Which frames `decode` and `plot` keep: some ESCs (`--esc`) and a window of receive times
//! (`--from`, `--to`).

use crate::error::CliError;

/// The selection options that `decode` and `plot` share.
#[derive(Debug, clap::Args)]
pub struct SelectArgs {
    /// Only these ESCs (indices as in the `esc` column; repeat or separate with commas).
    #[arg(long, value_name = "N", value_delimiter = ',')]
    pub esc: Vec<u8>,
    /// Only frames received at or after S seconds (`t_s`; needs inputs with receive times).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub from: Option<f64>,
    /// Only frames received before S seconds (`t_s`; needs inputs with receive times).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub to: Option<f64>,
}

impl SelectArgs {
    /// The window of receive times; an empty one is an error.
    pub fn window(&self) -> Result<Window, CliError> {
        Window::new(self.from, self.to)
    }
}

/// A window of receive times: `from <= t_s < to`, each end optional (`--to` is exclusive, so
/// that consecutive windows never share a frame).
#[derive(Debug, Clone, Copy)]
pub struct Window {
    /// Start, s (inclusive).
    pub from: f64,
    /// End, s (exclusive).
    pub to: f64,
}

impl Window {
    /// The window from `--from` and `--to`; an empty one is an error.
    pub fn new(from: Option<f64>, to: Option<f64>) -> Result<Window, CliError> {
        let window = Window {
            from: from.unwrap_or(f64::NEG_INFINITY),
            to: to.unwrap_or(f64::INFINITY),
        };
        // NaN and an empty window select nothing: say so rather than output nothing.
        if window.from.is_nan() || window.to.is_nan() || window.from >= window.to {
            return Err(CliError::EmptyWindow {
                from: window.from,
                to: window.to,
            });
        }
        Ok(window)
    }

    /// No window at all: every frame.
    pub const ALL: Window = Window {
        from: f64::NEG_INFINITY,
        to: f64::INFINITY,
    };

    /// Whether either end is given.
    pub fn is_limited(&self) -> bool {
        self.from > f64::NEG_INFINITY || self.to < f64::INFINITY
    }

    /// Whether a frame received at `t` is in the window (one without a time is, when there is
    /// no window).
    #[inline]
    pub fn contains(&self, t: Option<f64>) -> bool {
        match t {
            Some(t) => t >= self.from && t < self.to,
            None => !self.is_limited(),
        }
    }
}
