//! End-to-end tests of `hwfoc plot` (and `hwfoc summary --plot`): inputs made by the simulator,
//! images checked as images: PNG size and pixels (a row of panels per ESC, fault spans where
//! the faults were), SVG as XML (panels, unit labels, fault names); errors.

mod common;

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;
use std::process::Output;

use common::{Dir, XROTOR, assert_fails_with, capture, hwfoc, ok};

fn run(args: &[&str]) -> Output {
    hwfoc().args(args).output().expect("run hwfoc")
}

/// Three virtual ESCs recorded for 20 s (Unix time from 1000 s), ESC 1 overheating from 5 to
/// 7 s.
fn three_escs(dir: &Dir) -> String {
    let path = dir.arg("run.pcapng");
    ok(run(&[
        "simulate",
        "--escs",
        "3",
        "--duration",
        "20",
        "--start-time",
        "1000",
        "--fault",
        "1:mos_overheat@5-7",
        "-q",
        "-o",
        &path,
    ]));
    path
}

/// A decoded PNG: width, height, RGB bytes.
struct Png {
    width: u32,
    height: u32,
    rgb: Vec<u8>,
}

impl Png {
    fn read(path: &Path) -> Png {
        let decoder = png::Decoder::new(BufReader::new(File::open(path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(info.bit_depth, png::BitDepth::Eight);
        buf.truncate(info.buffer_size());
        Png {
            width: info.width,
            height: info.height,
            rgb: buf,
        }
    }

    fn pixel(&self, x: u32, y: u32) -> (u8, u8, u8) {
        let i = (y as usize * self.width as usize + x as usize) * 3;
        (self.rgb[i], self.rgb[i + 1], self.rgb[i + 2])
    }

    /// The rows of pixels that have a pixel for which `f` holds.
    fn rows_with(&self, f: impl Fn((u8, u8, u8)) -> bool) -> Vec<u32> {
        (0..self.height)
            .filter(|&y| (0..self.width).any(|x| f(self.pixel(x, y))))
            .collect()
    }

    /// The runs of at least 6 fault-shaded pixels in row `y`: (first, last) of each.
    fn shade_runs(&self, y: u32) -> Vec<(u32, u32)> {
        let xs: Vec<u32> = (0..self.width)
            .filter(|&x| is_fault_shade(self.pixel(x, y)))
            .collect();
        clusters(&xs, 1)
            .into_iter()
            .filter(|(a, b)| b - a >= 5)
            .collect()
    }

    /// The rows with fault shading (not just a stray pixel of anti-aliased red text).
    fn shaded_rows(&self) -> Vec<u32> {
        (0..self.height)
            .filter(|&y| !self.shade_runs(y).is_empty())
            .collect()
    }
}

/// Runs of numbers at most `gap` apart: (first, last) of each.
fn clusters(values: &[u32], gap: u32) -> Vec<(u32, u32)> {
    let mut out: Vec<(u32, u32)> = Vec::new();
    for &v in values {
        match out.last_mut() {
            Some((_, last)) if v - *last <= gap => *last = v,
            _ => out.push((v, v)),
        }
    }
    out
}

/// The speed line's colour: only the speed panel of each ESC's row has it.
fn is_speed_line(p: (u8, u8, u8)) -> bool {
    p == (44, 160, 44)
}

/// The light red of a fault span (over white or a grid line).
fn is_fault_shade(p: (u8, u8, u8)) -> bool {
    let (r, g, b) = p;
    r >= 240 && (200..=232).contains(&g) && (200..=232).contains(&b) && r - g >= 15
}

#[test]
fn png_has_the_requested_size_a_row_per_esc_and_the_fault_where_it_was() {
    let dir = Dir::new();
    let input = three_escs(&dir);
    let out = dir.path("run.png");
    ok(run(&[
        "plot",
        &input,
        "-o",
        out.to_str().unwrap(),
        "--width",
        "1400",
        "--height",
        "900",
    ]));
    let png = Png::read(&out);
    assert_eq!((png.width, png.height), (1400, 900));
    // One speed panel per ESC, one above the other.
    let rows = clusters(&png.rows_with(is_speed_line), 20);
    assert_eq!(rows.len(), 3, "speed panels at rows {rows:?}");
    // The fault is shaded in ESC 1's row only, in each of its six panels.
    let shaded = png.shaded_rows();
    assert!(!shaded.is_empty(), "no fault span drawn");
    let (first, last) = (shaded[0], *shaded.last().unwrap());
    assert!(
        first >= rows[0].1 && last <= rows[2].0 && first < rows[1].1 && last > rows[1].0,
        "fault shade at rows {first}..{last}, speed panels at {rows:?}"
    );
    // Near the bottom of the spans, on a few rows: a line along a panel's bottom (a current
    // or power of zero) may hide a span on one of them. Runs split where a line crosses the
    // span are one span.
    let mut xs: Vec<u32> = (last - 12..=last - 2)
        .step_by(5)
        .flat_map(|y| png.shade_runs(y))
        .flat_map(|(a, b)| [a, b])
        .collect();
    xs.sort_unstable();
    let spans = clusters(&xs, 40);
    assert_eq!(spans.len(), 6, "fault spans at columns {spans:?}");
    // 2 s of a 20 s axis: about a tenth of a panel's width.
    for (a, b) in &spans {
        assert!((10..=40).contains(&(b - a)), "span {a}..{b}");
    }
}

#[test]
fn default_height_grows_with_the_escs_shown() {
    let dir = Dir::new();
    let input = three_escs(&dir);
    let heights: Vec<(u32, usize)> = [None, Some("1"), Some("0,2")]
        .iter()
        .map(|esc| {
            let out = dir.path("x.png");
            let mut args = vec!["plot", &input, "--overwrite", "-o", out.to_str().unwrap()];
            if let Some(esc) = esc {
                args.extend(["--esc", esc]);
            }
            ok(run(&args));
            let png = Png::read(&out);
            assert_eq!(png.width, 1600);
            let rows = clusters(&png.rows_with(is_speed_line), 20).len();
            let faults = !png.shaded_rows().is_empty();
            assert_eq!(faults, esc.is_none_or(|e| e.contains('1')), "--esc {esc:?}");
            (png.height, rows)
        })
        .collect();
    assert_eq!(heights.iter().map(|h| h.1).collect::<Vec<_>>(), [3, 1, 2]);
    let (three, one, two) = (heights[0].0, heights[1].0, heights[2].0);
    assert!(one < two && two < three, "{heights:?}");
    assert_eq!(three - two, two - one, "a row per ESC: {heights:?}");
}

/// The SVG's text elements, trimmed, with how often each occurs.
fn svg_texts(svg: &str) -> BTreeMap<String, usize> {
    let doc = roxmltree::Document::parse(svg).expect("the SVG is well-formed XML");
    let mut texts = BTreeMap::new();
    for node in doc.descendants().filter(|n| n.has_tag_name("text")) {
        let text: String = node
            .children()
            .filter_map(|n| n.text())
            .collect::<String>()
            .trim()
            .to_string();
        *texts.entry(text).or_insert(0) += 1;
    }
    texts
}

#[test]
fn svg_is_xml_with_a_panel_set_per_esc_units_and_fault_names() {
    let dir = Dir::new();
    let input = three_escs(&dir);
    let out = dir.path("run.svg");
    ok(run(&[
        "plot",
        &input,
        "-o",
        out.to_str().unwrap(),
        "--width",
        "1500",
        "--height",
        "1000",
        "--title",
        "Bench run <3 & more",
    ]));
    let svg = std::fs::read_to_string(&out).unwrap();
    let doc = roxmltree::Document::parse(&svg).expect("well-formed XML");
    let root = doc.root_element();
    assert_eq!(root.tag_name().name(), "svg");
    assert_eq!(root.attribute("width"), Some("1500"));
    assert_eq!(root.attribute("height"), Some("1000"));
    let texts = svg_texts(&svg);
    let count = |t: &str| texts.get(t).copied().unwrap_or(0);
    assert_eq!(count("Bench run <3 & more"), 1, "{texts:?}");
    for esc in ["ESC 0", "ESC 1", "ESC 2"] {
        assert_eq!(count(esc), 1, "{esc}: {texts:?}");
    }
    for axis in [
        "throttle (%)",
        "speed (rpm)",
        "current (A)",
        "power (W)",
        "voltage (V)",
        "temperature (°C)",
    ] {
        assert_eq!(count(axis), 3, "{axis}: {texts:?}");
    }
    assert_eq!(count("time (s)"), 18, "{texts:?}");
    for legend in ["input", "output", "phase", "MOSFET", "capacitor"] {
        assert!(count(legend) >= 3, "{legend}: {texts:?}");
    }
    // The span's label in ESC 1's throttle panel, and ESC 1's header.
    assert_eq!(count("mos_overheat"), 1, "{texts:?}");
    let header = texts
        .keys()
        .find(|t| t.starts_with("fault: mos_overheat"))
        .unwrap_or_else(|| panic!("no fault header in {texts:?}"));
    // 5 to 7 s of simulated time from 1000 s after 1970 (the recording's wall clock), from
    // the first faulty frame to the last, in dates, as the summary gives it.
    let (start, end) = header
        .trim_start_matches("fault: mos_overheat, ")
        .split_once(" .. ")
        .unwrap_or_else(|| panic!("{header}"));
    assert!(start.starts_with("1970-01-01T00:16:45.0"), "{header}");
    assert!(
        end.starts_with("1970-01-01T00:16:46.9") || end.starts_with("1970-01-01T00:16:47.0"),
        "{header}"
    );
    assert_eq!(count("no faults"), 2, "{texts:?}");
    // Six shaded spans: ESC 1's panels.
    let spans = doc
        .descendants()
        .filter(|n| n.has_tag_name("rect") && n.attribute("fill") == Some("#D62728"))
        .count();
    assert_eq!(spans, 6);
    // Relative time from the recording's first frame, whose date is given (the recording's
    // clock is Unix time, from 1000 s).
    assert!(
        texts
            .keys()
            .any(|t| t.contains("from the first frame, 1970-01-01T00:16:40.002Z")),
        "{texts:?}"
    );
}

#[test]
fn inputs_without_receive_times_are_plotted_by_frame_index() {
    let dir = Dir::new();
    let raw = dir.arg("run.bin");
    ok(run(&["simulate", "--duration", "8", "-q", "-o", &raw]));
    let out = dir.path("raw.svg");
    ok(run(&["plot", &raw, "-o", out.to_str().unwrap()]));
    let texts = svg_texts(&std::fs::read_to_string(&out).unwrap());
    assert_eq!(texts.get("frame index × 0.05 (s)"), Some(&6), "{texts:?}");
    assert!(
        texts.keys().any(|t| t.contains("without receive times")),
        "{texts:?}"
    );
    // A time window needs receive times.
    let o = run(&["plot", &raw, "-o", &dir.arg("w.png"), "--from", "1"]);
    assert_fails_with(&o, "without receive times");
    assert!(!dir.path("w.png").exists());
}

#[test]
fn a_time_window_plots_only_its_frames() {
    let dir = Dir::new();
    let input = three_escs(&dir);
    let out = dir.path("window.svg");
    ok(run(&[
        "plot",
        &input,
        "-o",
        out.to_str().unwrap(),
        "--from",
        "1004",
        "--to",
        "1010",
        "--esc",
        "1",
    ]));
    let texts = svg_texts(&std::fs::read_to_string(&out).unwrap());
    assert!(texts.contains_key("ESC 1") && !texts.contains_key("ESC 0"));
    let subtitle = texts
        .keys()
        .find(|t| t.starts_with("1 ESC · "))
        .unwrap_or_else(|| panic!("no subtitle in {texts:?}"));
    // 6 s of frames; the axis counts from the recording's first frame (2 ms after the
    // start), as --from +S does.
    assert!(subtitle.starts_with("1 ESC · 6.0 s · "), "{subtitle}");
    assert!(
        subtitle.contains("window from +3.998 s to +9.998 s"),
        "{subtitle}"
    );
    let header = texts
        .keys()
        .find(|t| t.starts_with("fault: mos_overheat, "))
        .unwrap_or_else(|| panic!("no fault header in {texts:?}"));
    assert!(
        header.starts_with("fault: mos_overheat, 1970-01-01T00:16:45.0"),
        "{header}"
    );
    // A window that holds no frame says where the frames are.
    let o = run(&[
        "plot",
        &input,
        "-o",
        &dir.arg("none.png"),
        "--from",
        "5",
        "--to",
        "6",
    ]);
    assert_fails_with(&o, "nothing to plot: no frame in the time window");
    assert!(!dir.path("none.png").exists());
    let o = run(&[
        "plot",
        &input,
        "-o",
        &dir.arg("e.png"),
        "--from",
        "3",
        "--to",
        "3",
    ]);
    assert_fails_with(&o, "--from 3 is not before --to 3");
}

#[test]
fn summary_plot_writes_the_same_plot_and_the_same_summary() {
    let dir = Dir::new();
    let input = three_escs(&dir);
    let plain = ok(run(&["summary", &input])).stdout;
    let out = dir.path("summary.png");
    let with_plot = ok(run(&["summary", &input, "--plot", out.to_str().unwrap()])).stdout;
    assert_eq!(
        String::from_utf8(with_plot).unwrap(),
        String::from_utf8(plain).unwrap()
    );
    let png = Png::read(&out);
    assert_eq!(png.width, 1600);
    assert_eq!(clusters(&png.rows_with(is_speed_line), 20).len(), 3);
    let plot = dir.path("plot.png");
    ok(run(&["plot", &input, "-o", plot.to_str().unwrap()]));
    assert_eq!(std::fs::read(&plot).unwrap(), std::fs::read(&out).unwrap());
    // A wrong name is reported before anything is read or printed.
    let o = run(&["summary", &input, "--plot", &dir.arg("summary.jpg")]);
    assert_fails_with(&o, "use a name ending in .png or .svg");
    assert!(o.stdout.is_empty());
}

#[test]
fn the_demo_capture_plots() {
    let dir = Dir::new();
    let out = dir.path("demo.png");
    ok(run(&["plot", "--demo", "-o", out.to_str().unwrap()]));
    let png = Png::read(&out);
    assert_eq!(clusters(&png.rows_with(is_speed_line), 20).len(), 1);
}

#[test]
fn bad_outputs_and_empty_inputs_are_errors() {
    let dir = Dir::new();
    let input = three_escs(&dir);
    let o = run(&["plot", &input, "-o", &dir.arg("plot.jpg")]);
    assert_fails_with(&o, "-o ");
    assert_fails_with(&o, "use a name ending in .png or .svg");
    assert!(!dir.path("plot.jpg").exists());
    let o = run(&["plot", &input, "-o", &dir.arg("missing/plot.png")]);
    assert_fails_with(&o, "does not exist");
    let o = run(&["plot", &input, "-o", dir.0.path().to_str().unwrap()]);
    assert_fails_with(&o, "use a name ending in .png or .svg");
    let subdir = dir.path("d.png");
    std::fs::create_dir(&subdir).unwrap();
    let o = run(&["plot", &input, "-o", subdir.to_str().unwrap()]);
    assert_fails_with(&o, "it is a directory");
    let o = run(&["plot", &input, "-o", &dir.arg("x.png"), "--esc", "7"]);
    assert_fails_with(
        &o,
        "nothing to plot: --esc 7: the inputs have only ESCs 0 to 2",
    );
    assert!(!dir.path("x.png").exists());
    let o = run(&["plot", &input, "-o", &dir.arg("x.png"), "--width", "10"]);
    assert_eq!(o.status.code(), Some(2), "a usage error from clap");
    // Bytes that hold no frame: nothing is written, and an existing file is kept as it was.
    let noise = dir.path("noise.bin");
    std::fs::write(&noise, [0x55u8; 4096]).unwrap();
    let existing = dir.path("old.png");
    std::fs::write(&existing, b"an older plot").unwrap();
    let o = run(&[
        "plot",
        noise.to_str().unwrap(),
        "--overwrite",
        "-o",
        existing.to_str().unwrap(),
    ]);
    assert_fails_with(&o, "nothing to plot");
    assert_fails_with(&o, "no valid frame of any Hobbywing format");
    assert_eq!(std::fs::read(&existing).unwrap(), b"an older plot");
    let o = run(&["plot", &dir.arg("absent.pcapng"), "-o", &dir.arg("y.svg")]);
    assert_fails_with(&o, "cannot open");
    assert!(!dir.path("y.svg").exists());
}

/// Lines stay inside their panels: on the real XRotor capture, one-frame spikes (phase current,
/// power, voltage) turn straight back, and the PNG backend's mitred joins ran from them through
/// the header text and the axis labels to the image's edge. The speed/power green and the
/// voltage purple are only drawn between the top of the plotting areas (where the y axes
/// start) and the x axes.
#[test]
fn lines_stay_inside_their_panels() {
    let dir = Dir::new();
    let out = dir.path("x.png");
    let input = capture(XROTOR);
    ok(run(&[
        "plot",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--no-config",
    ]));
    let png = Png::read(&out);
    const AXIS: (u8, u8, u8) = (120, 120, 120);
    // The x axes: rows with a long run of the axis colour; the y axes: columns with one.
    let x_axis = (0..png.height)
        .filter(|&y| (0..png.width).filter(|&x| png.pixel(x, y) == AXIS).count() > 100)
        .max()
        .expect("an x axis");
    let top = (0..png.width)
        .filter_map(|x| {
            let rows: Vec<u32> = (0..png.height)
                .filter(|&y| png.pixel(x, y) == AXIS)
                .collect();
            (rows.len() > 100).then(|| rows[0])
        })
        .max()
        .expect("a y axis");
    let line = |p: (u8, u8, u8)| p == (44, 160, 44) || p == (148, 103, 189);
    let rows = png.rows_with(line);
    assert!(!rows.is_empty() && top > 60, "top {top}");
    assert!(
        rows.iter().all(|&y| (top..=x_axis).contains(&y)),
        "line pixels in rows {:?}, outside the panels' rows {top}..={x_axis}",
        rows.iter()
            .filter(|&&y| !(top..=x_axis).contains(&y))
            .collect::<Vec<_>>()
    );
}

/// A fault episode has the same times in the plot's header as in the summary: from its first
/// to its last faulty frame, on the source's clock (dates for a recording); the demo's
/// throttle-signal-lost episode was "4.77 to 5.07 s" in one and "5.020 .. 5.270 s" in the other.
#[test]
fn a_fault_episode_has_the_same_times_in_the_plot_and_the_summary() {
    let dir = Dir::new();
    let recording = dir.path("rec.pcapng");
    ok(run(&[
        "simulate",
        "--duration",
        "6",
        "--start-time",
        "1700000000",
        "--fault",
        "mos_overheat@2-3",
        "--no-config",
        "-o",
        recording.to_str().unwrap(),
    ]));
    for input in [vec!["--demo"], vec![recording.to_str().unwrap()]] {
        let summary =
            String::from_utf8(ok(run(&[&["summary"], &input[..]].concat())).stdout).unwrap();
        // `     1  5.020 .. 5.270 s (0.250 s, ...` or `     1  2023-… .. 2023-… (1.0 s, ...`
        let episode = summary
            .lines()
            .find(|l| l.trim_start().starts_with("1  "))
            .unwrap_or_else(|| panic!("no episode in {summary}"));
        let when = episode.trim_start()[3..]
            .split(" (")
            .next()
            .unwrap()
            .to_string();
        let svg = dir.path("p.svg");
        let mut args = vec!["plot"];
        args.extend(&input);
        args.extend(["--overwrite", "-o", svg.to_str().unwrap()]);
        let o = run(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(
            text.lines()
                .any(|l| l.trim_end().ends_with(&format!(", {when}"))),
            "the plot's header lacks {when:?} (summary: {episode})"
        );
    }
}
