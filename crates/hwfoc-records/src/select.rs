//! Which frames to keep: some ESCs and a window of receive times (`hwfoc decode` and `plot`
//! with `--esc`, `--from`, `--to`).

use std::fmt;

use crate::time::Time;

/// A window of receive times: `from <= t_s < to`, each end optional (`to` is exclusive, so
/// that consecutive windows never share a frame).
///
/// An end may be given in seconds after the first frame ([`Time::FromFirst`]): the window is
/// then resolved when it first sees a frame with a time ([`Window::observe`]), which every
/// handler does for every data frame, of every ESC, before choosing by ESC. So "the first
/// frame" is the first data frame with a time that the inputs give, whichever ESC it is of;
/// [`crate::Sources`] hands frames of inputs given together in time order, so it is
/// the earliest one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// Start, s (inclusive); before the window is resolved, minus infinity for an end after
    /// the first frame.
    pub from: f64,
    /// End, s (exclusive); before the window is resolved, infinity for an end after the first
    /// frame.
    pub to: f64,
    /// Ends after the first frame not resolved yet: seconds after it.
    after_first: [Option<f64>; 2],
    /// The time of the first frame, once seen.
    origin: Option<f64>,
    /// Whether an end was a date-time.
    dated: bool,
}

impl Window {
    /// The window from an optional start and end in the source's seconds; an empty one is an
    /// error.
    pub fn new(from: Option<f64>, to: Option<f64>) -> Result<Window, EmptyWindow> {
        Window::from_times(from.map(Time::Seconds), to.map(Time::Seconds))
    }

    /// The window from times as given on the command line. An empty window is an error when
    /// both ends are of the same kind (both after the first frame, or both not); one of each
    /// is known only when resolved, and then selects nothing if empty.
    pub fn from_times(from: Option<Time>, to: Option<Time>) -> Result<Window, EmptyWindow> {
        let fixed = |t: Option<Time>, open: f64| match t {
            Some(Time::Seconds(s) | Time::Date(s)) => s,
            _ => open,
        };
        let after = |t: Option<Time>| match t {
            Some(Time::FromFirst(s)) => Some(s),
            _ => None,
        };
        let window = Window {
            from: fixed(from, f64::NEG_INFINITY),
            to: fixed(to, f64::INFINITY),
            after_first: [after(from), after(to)],
            origin: None,
            dated: from.is_some_and(|t| t.is_date()) || to.is_some_and(|t| t.is_date()),
        };
        let empty = |a: f64, b: f64| a.is_nan() || b.is_nan() || a >= b;
        let relative = matches!(window.after_first, [Some(_), Some(_)]);
        let (a, b) = match window.after_first {
            [Some(a), Some(b)] => (a, b),
            _ => (window.from, window.to),
        };
        // NaN and an empty window select nothing: say so rather than output nothing.
        if empty(a, b) && (relative || window.after_first == [None, None]) {
            return Err(EmptyWindow {
                from: a,
                to: b,
                relative,
            });
        }
        Ok(window)
    }

    /// No window at all: every frame.
    pub const ALL: Window = Window {
        from: f64::NEG_INFINITY,
        to: f64::INFINITY,
        after_first: [None, None],
        origin: None,
        dated: false,
    };

    /// Whether either end is given.
    pub fn is_limited(&self) -> bool {
        self.from > f64::NEG_INFINITY
            || self.to < f64::INFINITY
            || self.after_first.iter().any(Option::is_some)
    }

    /// Whether an end was given as a date-time, which only inputs with a wall clock have
    /// (see [`crate::time::Clock`]).
    pub fn is_dated(&self) -> bool {
        self.dated
    }

    /// The time of the first frame with a time seen by [`Window::observe`].
    pub fn origin(&self) -> Option<f64> {
        self.origin
    }

    /// Takes note of a frame received at `t`: the first with a time resolves the ends given
    /// after the first frame. Call it for every data frame, before choosing by ESC.
    #[inline]
    pub fn observe(&mut self, t: Option<f64>) {
        if self.origin.is_none()
            && let Some(t) = t
        {
            self.resolve(t);
        }
    }

    #[cold]
    fn resolve(&mut self, first: f64) {
        self.origin = Some(first);
        if let Some(s) = self.after_first[0].take() {
            self.from = first + s;
        }
        if let Some(s) = self.after_first[1].take() {
            self.to = first + s;
        }
    }

    /// Whether a frame received at `t` is in the window (one without a time is, when there is
    /// no window). A frame with a time resolves the window first (see [`Window::observe`]);
    /// until then, a window with an end after the first frame holds no frame.
    #[inline]
    pub fn contains(&mut self, t: Option<f64>) -> bool {
        self.observe(t);
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
    /// Whether both are seconds after the first frame.
    pub relative: bool,
}

impl EmptyWindow {
    /// The message with the start and the end named as a front end names them (`--from` and
    /// `--to` in the command, `start=` and `end=` in Python): `--from 2 is not before --to 1:
    /// no frame can be selected`.
    pub fn between<'a>(&'a self, start: &'a str, end: &'a str) -> impl fmt::Display + 'a {
        struct Named<'a>(&'a EmptyWindow, &'a str, &'a str);
        impl fmt::Display for Named<'_> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                let Named(w, start, end) = self;
                let sign = if w.relative { "+" } else { "" };
                write!(
                    f,
                    "{start} {sign}{} is not before {end} {sign}{}: no frame can be selected",
                    w.from, w.to
                )
            }
        }
        Named(self, start, end)
    }
}

/// The message naming no front end's options: `the start 2 is not before the end 1: ...`.
impl fmt::Display for EmptyWindow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.between("the start", "the end").fmt(f)
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

    /// Whether a frame of ESC `esc` received at `t` is selected; its time is seen by the
    /// window whatever its ESC (see [`Window::observe`]).
    #[inline]
    pub fn contains(&mut self, esc: u8, t: Option<f64>) -> bool {
        self.window.observe(t);
        self.esc(esc) && self.window.contains(t)
    }
}

/// The selection as every output records it (the `filter` of the Parquet metadata and of the
/// Python package's schema, the CSV comment, the empty window's warning): `esc=0,2 from=+1.5
/// to=1795442580`, each part only when given (times as [`Time`] writes them), or empty.
pub fn filter_text(escs: &[u8], from: Option<Time>, to: Option<Time>) -> String {
    let mut parts = Vec::new();
    if !escs.is_empty() {
        let escs: Vec<String> = escs.iter().map(u8::to_string).collect();
        parts.push(format!("esc={}", escs.join(",")));
    }
    if let Some(from) = from {
        parts.push(format!("from={from}"));
    }
    if let Some(to) = to {
        parts.push(format!("to={to}"));
    }
    parts.join(" ")
}

/// The warning for a time window that held no frame of the selected ESCs, naming the window
/// as `filter` writes it (`from=100 to=200`) and the times the frames do have (`first` and
/// `last`, seconds; `wall`: the source's clock is the wall clock). The one wording of the
/// command's warning and of the Python package's `HwfocWarning`.
pub fn no_frame_in_window(filter: &str, first: f64, last: f64, wall: bool) -> String {
    format!(
        "no frame in the time window ({filter}): {}",
        crate::time::span_text(first, last, wall)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_and_escs() {
        let mut w = Window::new(Some(1.0), Some(2.0)).unwrap();
        assert!(w.contains(Some(1.0)) && !w.contains(Some(2.0)) && !w.contains(None));
        let mut all = Window::ALL;
        assert!(all.contains(None) && !all.is_limited());
        let empty = Window::new(Some(2.0), Some(2.0)).unwrap_err();
        assert_eq!(
            empty.to_string(),
            "the start 2 is not before the end 2: no frame can be selected"
        );
        assert_eq!(
            empty.between("--from", "--to").to_string(),
            "--from 2 is not before --to 2: no frame can be selected"
        );
        assert!(Window::new(Some(f64::NAN), None).is_err());
        let mut s = Selection::new(&[1, 3], w);
        assert!(s.contains(3, Some(1.5)) && !s.contains(2, Some(1.5)) && !s.contains(1, Some(3.0)));
        assert!(Selection::default().contains(255, None));
    }

    #[test]
    fn ends_after_the_first_frame_resolve_at_the_first_timed_frame() {
        let mut w =
            Window::from_times(Some(Time::FromFirst(5.0)), Some(Time::FromFirst(10.0))).unwrap();
        assert!(w.is_limited() && w.origin().is_none());
        // Untimed frames resolve nothing, and are not in a limited window.
        assert!(!w.contains(None));
        assert!(w.origin().is_none());
        assert!(!w.contains(Some(100.0)));
        assert_eq!(w.origin(), Some(100.0));
        assert_eq!((w.from, w.to), (105.0, 110.0));
        assert!(w.contains(Some(105.0)) && w.contains(Some(109.99)) && !w.contains(Some(110.0)));
        // Later frames do not move it.
        w.observe(Some(50.0));
        assert_eq!((w.from, w.to, w.origin()), (105.0, 110.0, Some(100.0)));
        // The first frame of the inputs counts, whichever ESC is selected.
        let mut s = Selection::new(
            &[1],
            Window::from_times(Some(Time::FromFirst(1.0)), None).unwrap(),
        );
        assert!(!s.contains(0, Some(10.0)));
        assert!(s.contains(1, Some(11.0)) && !s.contains(1, Some(10.5)));
    }

    #[test]
    fn the_filter_text_names_what_was_given() {
        assert_eq!(filter_text(&[], None, None), "");
        assert_eq!(
            filter_text(
                &[0, 2],
                Some(Time::FromFirst(1.5)),
                Some(Time::Seconds(3.0))
            ),
            "esc=0,2 from=+1.5 to=3"
        );
        assert_eq!(
            filter_text(&[], None, Some(Time::Seconds(1700000002.0))),
            "to=1700000002"
        );
    }

    #[test]
    fn mixed_ends_and_empty_windows() {
        let e = Window::from_times(Some(Time::FromFirst(10.0)), Some(Time::FromFirst(5.0)))
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "the start +10 is not before the end +5: no frame can be selected"
        );
        // One end of each kind: known only once resolved; empty then, it selects nothing.
        let mut w =
            Window::from_times(Some(Time::FromFirst(10.0)), Some(Time::Seconds(105.0))).unwrap();
        assert!(!w.contains(Some(100.0)) && !w.contains(Some(104.0)) && !w.contains(Some(111.0)));
        let mut w =
            Window::from_times(Some(Time::Date(100.0)), Some(Time::FromFirst(2.0))).unwrap();
        assert!(w.is_dated());
        assert!(!w.contains(Some(99.0)) && w.contains(Some(100.5)) && !w.contains(Some(101.0)));
        assert!(!Window::new(Some(1.0), None).unwrap().is_dated());
    }
}
