//! Which frames to keep: some ESCs and a window of receive times (`hwfoc decode` and `plot`
//! with `--esc`, `--from`, `--to`).

use std::fmt;

/// A window of receive times: `from <= t_s < to`, each end optional (`to` is exclusive, so
/// that consecutive windows never share a frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// Start, s (inclusive).
    pub from: f64,
    /// End, s (exclusive).
    pub to: f64,
}

impl Window {
    /// The window from an optional start and end; an empty one is an error.
    pub fn new(from: Option<f64>, to: Option<f64>) -> Result<Window, EmptyWindow> {
        let window = Window {
            from: from.unwrap_or(f64::NEG_INFINITY),
            to: to.unwrap_or(f64::INFINITY),
        };
        // NaN and an empty window select nothing: say so rather than output nothing.
        if window.from.is_nan() || window.to.is_nan() || window.from >= window.to {
            return Err(EmptyWindow {
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

/// A window whose start is not before its end: no frame can be in it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmptyWindow {
    /// Start of the window, s.
    pub from: f64,
    /// End of the window, s.
    pub to: f64,
}

impl fmt::Display for EmptyWindow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "--from {} is not before --to {}: no frame can be selected",
            self.from, self.to
        )
    }
}

impl std::error::Error for EmptyWindow {}

/// Some ESCs (all, or those named) and a window of receive times.
#[derive(Debug, Clone)]
pub struct Selection {
    escs: [bool; 256],
    /// The window of receive times.
    pub window: Window,
}

impl Default for Selection {
    fn default() -> Self {
        Selection::new(&[], Window::ALL)
    }
}

impl Selection {
    /// The ESCs numbered in `escs` (every ESC when empty) in `window`.
    pub fn new(escs: &[u8], window: Window) -> Selection {
        let mut wanted = [escs.is_empty(); 256];
        for &esc in escs {
            wanted[usize::from(esc)] = true;
        }
        Selection {
            escs: wanted,
            window,
        }
    }

    /// Whether ESC `esc` is selected.
    #[inline]
    pub fn esc(&self, esc: u8) -> bool {
        self.escs[usize::from(esc)]
    }

    /// Whether a frame of ESC `esc` received at `t` is selected.
    #[inline]
    pub fn contains(&self, esc: u8, t: Option<f64>) -> bool {
        self.esc(esc) && self.window.contains(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_and_escs() {
        let w = Window::new(Some(1.0), Some(2.0)).unwrap();
        assert!(w.contains(Some(1.0)) && !w.contains(Some(2.0)) && !w.contains(None));
        assert!(Window::ALL.contains(None) && !Window::ALL.is_limited());
        assert_eq!(
            Window::new(Some(2.0), Some(2.0)).unwrap_err().to_string(),
            "--from 2 is not before --to 2: no frame can be selected"
        );
        assert!(Window::new(Some(f64::NAN), None).is_err());
        let s = Selection::new(&[1, 3], w);
        assert!(s.contains(3, Some(1.5)) && !s.contains(2, Some(1.5)) && !s.contains(1, Some(3.0)));
        assert!(Selection::default().contains(255, None));
    }
}
