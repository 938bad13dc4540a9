//! Drawing a plot: a title, then per ESC a header line and a row of five panels (throttle,
//! speed, currents, voltage, temperatures) on one time axis, fault spans shaded.
//!
//! Every ESC's panels share the time axis, and each column of panels one value axis, so
//! that ESCs compare at a glance. Text uses DejaVu Sans, compiled in.

use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{FontStyle, register_font};

use crate::error::CliError;
use hwfoc_io::Escaped;
use hwfoc_io::Fixed;
use hwfoc_io::Sources;
use hwfoc_io::summary::no_frames;
use hwfoc_io::time::{self, Clock};

use super::collect::{Bucket, Collector, EscData, Span};
use super::target::{ImageFile, ImageFormat};
use super::text::Glyphs;
use super::{MAX_SIZE, Options};
use crate::shown::{Measure, Shown};
use hwfoc::Quantity;

/// The width of an image unless `--width` is given, px.
pub const DEFAULT_WIDTH: u32 = 1600;

/// Height of the title band, px.
const TITLE_H: u32 = 62;
/// Height of an ESC's row (header and panels) when the image's height is not given, px.
const ROW_H: u32 = 300;
/// Height of an ESC's header line, px.
const HEADER_H: u32 = 28;
/// Height of a panel's caption (name and legend), px.
const CAPTION_H: u32 = 20;
/// Space below the last row, px.
const BOTTOM_H: u32 = 8;
/// Margin left and right of the image, px.
const SIDE: u32 = 10;
/// Width of a panel's value-axis labels, px.
const Y_LABELS_W: u32 = 62;
/// Height of a panel's time-axis labels, px.
const X_LABELS_H: u32 = 38;

/// Lines of fault names at the top of the first panel.
const LABEL_LINES: usize = 3;

/// Tick labels per axis, at most.
const TICKS: usize = 6;

/// The font family name the embedded font is registered under.
const FONT: &str = "sans-serif";

const TEXT: RGBColor = RGBColor(30, 30, 30);
const MUTED: RGBColor = RGBColor(100, 100, 100);
const GRID: RGBColor = RGBColor(225, 225, 225);
const AXIS: RGBColor = RGBColor(120, 120, 120);
const FAULT: RGBColor = RGBColor(214, 39, 40);
const FAULT_TEXT: RGBColor = RGBColor(170, 20, 20);
/// The windows of `hwfoc check`'s warnings and critical findings.
const WARNING: RGBColor = RGBColor(255, 190, 0);
const CRITICAL: RGBColor = RGBColor(148, 60, 189);
const OK_TEXT: RGBColor = RGBColor(40, 130, 60);
const BLUE: RGBColor = RGBColor(31, 119, 180);
const ORANGE: RGBColor = RGBColor(255, 127, 14);
const GREEN: RGBColor = RGBColor(44, 160, 44);
const PURPLE: RGBColor = RGBColor(148, 103, 189);
const RED: RGBColor = RGBColor(200, 40, 40);
const TEAL: RGBColor = RGBColor(23, 160, 180);

/// How a panel's value axis is chosen from its values.
#[derive(Debug, Clone, Copy)]
enum Scale {
    /// 0 to 100 %, or more if a value is above.
    Percent,
    /// From zero (or the lowest value, if negative) to the highest value.
    FromZero,
    /// The values' range, at least this wide.
    Auto(f64),
}

/// One panel of an ESC's row: the quantities of one [`Measure`].
struct Panel {
    /// Caption.
    title: &'static str,
    /// Value axis description, with the unit.
    axis: String,
    /// The lines: quantity, legend text, colour.
    lines: Vec<(Shown, &'static str, RGBColor)>,
    scale: Scale,
}

impl Panel {
    /// The panel of the quantities of `measure`.
    fn of(measure: Measure) -> Panel {
        Panel {
            title: measure.title(),
            axis: format!("{} ({})", measure.title().to_lowercase(), measure.unit()),
            lines: measure
                .shown()
                .map(|q| (q, q.legend(), colour(q)))
                .collect(),
            scale: match measure {
                Measure::Throttle => Scale::Percent,
                Measure::Speed | Measure::Current | Measure::Power => Scale::FromZero,
                Measure::Voltage => Scale::Auto(1.0),
                Measure::Temperature => Scale::Auto(10.0),
            },
        }
    }
}

impl Panel {
    /// The panel with the lines of the quantities a frame of `protocol` carries (every line
    /// before a frame told the format).
    fn carried_by(&self, protocol: Option<hwfoc::Protocol>) -> Panel {
        Panel {
            lines: self
                .lines
                .iter()
                .filter(|(q, _, _)| protocol.is_none_or(|p| q.carried_by(p)))
                .copied()
                .collect(),
            axis: self.axis.clone(),
            ..*self
        }
    }
}

/// How many panels a row has.
const PANELS: usize = Measure::ALL.len();

/// The panels of a row, left to right.
fn panels() -> [Panel; PANELS] {
    Measure::ALL.map(Panel::of)
}

/// The colour of a quantity's line: the first of a panel's blue (green where it is alone),
/// the second orange; the voltage purple, the temperatures red and teal.
fn colour(q: Shown) -> RGBColor {
    match q {
        Shown::Carried(Quantity::Voltage) => PURPLE,
        Shown::Carried(Quantity::MosTemp) => RED,
        Shown::Carried(Quantity::CapTemp) => TEAL,
        // HW5's: apart from every HW-FOC line's colour of their panel.
        Shown::Carried(Quantity::MotorTemp | Quantity::BecVoltage) => ORANGE,
        Shown::Carried(Quantity::BecTemp) => BLUE,
        Shown::Carried(Quantity::BecCurrent) => GREEN,
        _ => {
            let Some(m) = q.measure() else {
                return ORANGE;
            };
            match (m.shown().position(|s| s == q), m.shown().count()) {
                (Some(0), 1) => GREEN,
                (Some(0), _) => BLUE,
                _ => ORANGE,
            }
        }
    }
}

/// The height that gives every one of `rows` ESCs a full row.
fn default_height(rows: usize) -> u32 {
    let h = TITLE_H as usize + rows * ROW_H as usize + BOTTOM_H as usize;
    h.min(MAX_SIZE as usize) as u32
}

/// Registers the embedded font with plotters, once.
fn register_fonts() -> Result<(), CliError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        register_font(FONT, FontStyle::Normal, dejavu::sans::regular()).is_ok()
            && register_font(FONT, FontStyle::Bold, dejavu::sans::bold()).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(CliError::Render {
            output: String::new(),
            message: "the embedded font could not be loaded".to_string(),
        })
    }
}

impl Collector {
    /// Draws the plot of what was read from `sources` and writes it to `target`.
    pub fn write(
        &mut self,
        sources: &Sources,
        options: &Options,
        target: &mut ImageFile,
    ) -> Result<(), CliError> {
        self.finish();
        let image = render(self, sources, options, target)?;
        target.write(&image)
    }
}

/// Draws the plot and returns the file's bytes.
pub fn render(
    collector: &Collector,
    sources: &Sources,
    options: &Options,
    target: &ImageFile,
) -> Result<Vec<u8>, CliError> {
    let scene = Scene::new(collector, sources, options)?;
    register_fonts()?;
    let width = options.width;
    let height = options
        .height
        .unwrap_or_else(|| default_height(scene.rows.len()));
    let failed = |message: String| CliError::Render {
        output: target.name().to_string(),
        message,
    };
    match target.format() {
        ImageFormat::Png => {
            let mut rgb = vec![255u8; width as usize * height as usize * 3];
            {
                let bitmap = BitMapBackend::with_buffer(&mut rgb, (width, height));
                let root = Glyphs::new(bitmap).into_drawing_area();
                scene.draw(&root).map_err(|e| failed(e.to_string()))?;
                root.present().map_err(|e| failed(e.to_string()))?;
            }
            encode_png(&rgb, width, height).map_err(|e| failed(e.to_string()))
        }
        ImageFormat::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
                scene.draw(&root).map_err(|e| failed(e.to_string()))?;
                root.present().map_err(|e| failed(e.to_string()))?;
            }
            Ok(svg.into_bytes())
        }
    }
}

/// An 8-bit RGB image as PNG.
fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(out)
}

/// One ESC's row.
struct Row<'a> {
    /// Its index.
    esc: usize,
    /// Its frames, if any were plotted.
    data: Option<&'a EscData>,
    /// Clock value at x = 0.
    offset: f64,
    /// Where it came from: input, and stream where the input has several.
    source: String,
    /// Its device information.
    info: Option<String>,
    /// Why nothing is drawn, when nothing is.
    empty: Option<String>,
    /// Whether its input's clock is the wall clock (its episode is given in dates).
    wall: bool,
}

/// The time axis shared by all rows.
#[derive(Debug, Clone, Copy)]
struct TimeAxis {
    lo: f64,
    hi: f64,
}

/// Everything drawn, ready.
struct Scene<'a> {
    title: String,
    subtitle: String,
    rows: Vec<Row<'a>>,
    time: TimeAxis,
    /// Value axis of each panel column.
    ranges: [(f64, f64); PANELS],
    /// The panels of every row.
    panels: [Panel; PANELS],
}

impl<'a> Scene<'a> {
    fn new(
        collector: &'a Collector,
        sources: &Sources,
        options: &Options,
    ) -> Result<Scene<'a>, CliError> {
        let found = sources.escs().len();
        let shown: Vec<usize> = (0..found).filter(|&i| collector.wanted(i)).collect();
        if shown.is_empty() {
            let have = match found {
                0 => "no ESC".to_string(),
                1 => "only ESC 0".to_string(),
                n => format!("only ESCs 0 to {}", n - 1),
            };
            let message = if options.escs.is_empty() || found == 0 {
                format!("the inputs have {have}")
            } else {
                let asked: Vec<String> = options.escs.iter().map(u8::to_string).collect();
                format!("--esc {}: the inputs have {have}", asked.join(","))
            };
            return Err(CliError::NothingToPlot { message });
        }
        let plotted = |i: usize| collector.esc(i).filter(|d| d.plotted > 0);
        if shown.iter().all(|&i| plotted(i).is_none()) {
            return Err(CliError::NothingToPlot {
                message: nothing_message(collector, sources, &shown),
            });
        }
        // Timed ESCs count from the first frame of the inputs (as `--from +S` does); the
        // others from their frame 0.
        let earliest = shown
            .iter()
            .filter_map(|&i| plotted(i).filter(|d| d.timed))
            .filter_map(|d| d.clock.map(|c| c.0))
            .fold(f64::INFINITY, f64::min);
        let t0 = collector.origin().unwrap_or(earliest);
        let rows: Vec<Row> = shown
            .iter()
            .map(|&i| {
                let data = plotted(i);
                let stats = sources.link(i);
                let empty = match collector.esc(i) {
                    Some(d) if d.plotted > 0 => None,
                    Some(d) if d.frames > 0 => Some("no data frame in the time window".into()),
                    _ if stats.bytes() == 0 => Some("no bytes from this stream".into()),
                    _ if stats.frames() == 0 => Some(no_frames(sources, i)),
                    _ => Some("no data frames".into()),
                };
                Row {
                    esc: i,
                    data,
                    offset: if data.is_some_and(|d| d.timed) {
                        t0
                    } else {
                        0.0
                    },
                    source: Escaped(source_name(sources, i)).to_string(),
                    info: collector
                        .esc(i)
                        .and_then(|d| d.info)
                        .map(|info| Escaped(info).to_string()),
                    empty,
                    wall: sources
                        .inputs()
                        .get(sources.esc_table()[i].input)
                        .is_some_and(|input| input.format.clock() == Clock::Wall),
                }
            })
            .collect();
        let mut time = TimeAxis {
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
        };
        for row in &rows {
            if let Some(d) = row.data
                && let Some((first, last)) = d.clock
            {
                time.lo = time.lo.min(first - row.offset);
                time.hi = time.hi.max(last - row.offset + d.period());
            }
        }
        if time.hi - time.lo < 1.0 {
            time.hi = time.lo + 1.0;
        }
        let settings = *collector.settings();
        let panels = panels();
        let ranges = std::array::from_fn(|p| value_range(&panels[p], &rows));
        let timed = rows.iter().any(|r| r.data.is_some_and(|d| d.timed));
        let untimed = rows.iter().any(|r| r.data.is_some_and(|d| !d.timed));
        let title = options.title.clone().unwrap_or_else(|| {
            let names: Vec<String> = sources
                .names()
                .iter()
                .map(|n| Escaped(n).to_string())
                .collect();
            match names.len() {
                0..=3 => names.join(", "),
                n => format!("{}, … ({n} inputs)", names[..2].join(", ")),
            }
        });
        let mut subtitle = format!(
            "{} · {:.1} s",
            match rows.len() {
                1 => "1 ESC".to_string(),
                n => format!("{n} ESCs"),
            },
            time.hi - time.lo
        );
        // Dates where every plotted timed ESC's input has a wall clock.
        let wall = rows
            .iter()
            .filter(|r| r.data.is_some_and(|d| d.timed))
            .all(|r| {
                let input = sources.esc_table()[r.esc].input;
                sources
                    .inputs()
                    .get(input)
                    .is_some_and(|i| i.format.clock() == Clock::Wall)
            });
        if timed {
            if wall {
                subtitle.push_str(&format!(
                    " · time in seconds from the first frame, {}",
                    time::iso8601(t0)
                ));
            } else {
                subtitle.push_str(&format!(
                    " · time in seconds from the first frame (t_s = {t0:.3}, the source's clock)"
                ));
            }
        }
        if untimed {
            // Each protocol's frame period, once.
            let mut periods: Vec<f64> = Vec::new();
            for d in rows.iter().filter_map(|r| r.data).filter(|d| !d.timed) {
                if !periods.contains(&d.period()) {
                    periods.push(d.period());
                }
            }
            let periods: Vec<String> = periods.iter().map(|p| format!("{p}")).collect();
            subtitle.push_str(&format!(
                " · {}inputs without receive times: data frame index × {} s",
                if timed { "" } else { "time: " },
                periods.join(" or ")
            ));
        }
        let jumps: u64 = rows
            .iter()
            .filter_map(|r| r.data)
            .map(|d| d.discontinuities)
            .sum();
        if jumps > 0 {
            subtitle.push_str(&format!(
                " · {jumps} clock discontinuit{} (a step back or a jump): the time axis goes on \
                 across {}, lines break there",
                if jumps == 1 { "y" } else { "ies" },
                if jumps == 1 { "it" } else { "them" }
            ));
        }
        let window = collector.window();
        if window.is_limited() && timed {
            subtitle.push_str(" · window");
            if window.from > f64::NEG_INFINITY {
                subtitle.push_str(&format!(" from {:+.3} s", window.from - t0));
            }
            if window.to < f64::INFINITY {
                subtitle.push_str(&format!(" to {:+.3} s", window.to - t0));
            }
        }
        subtitle.push_str(&format!(
            " · current scale {}/A, {} pole pairs, gear ratio {}",
            settings.current_scale, settings.pole_pairs, settings.gear_ratio
        ));
        Ok(Scene {
            title,
            subtitle,
            rows,
            time,
            ranges,
            panels,
        })
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let (w, h) = root.dim_in_pixel();
        let area = root.margin(0, BOTTOM_H.min(h / 4), SIDE, SIDE);
        let (title, body) = area.split_vertically(TITLE_H.min(h / 3));
        let width = w.saturating_sub(2 * SIDE) as i32;
        let style = bold(20, TEXT);
        let fitted = fit(&title, &self.title, &style, width)?;
        title.draw_text(&fitted, &style, (0, 8))?;
        let style = text(13, MUTED);
        let fitted = fit(&title, &self.subtitle, &style, width)?;
        title.draw_text(&fitted, &style, (0, 36))?;
        let row_h = body.dim_in_pixel().1 / self.rows.len().max(1) as u32;
        let mut rest = body;
        for row in &self.rows {
            let (this, next) = rest.split_vertically(row_h);
            self.draw_row(&this, row)?;
            rest = next;
        }
        Ok(())
    }

    fn draw_row<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        row: &Row,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let (header, body) = area.split_vertically(HEADER_H);
        let width = header.dim_in_pixel().0 as i32;
        // A rule above each ESC's row.
        header.draw(&PathElement::new(
            vec![(0, 2), (width, 2)],
            GRID.stroke_width(2),
        ))?;
        let name = bold(16, TEXT);
        let label = format!("ESC {}", row.esc);
        header.draw_text(&label, &name, (0, 9))?;
        let x = header.estimate_text_size(&label, &name)?.0 as i32 + 14;
        let (faults, colour) = match row.data {
            Some(d) => fault_summary(d, row.wall),
            None => (String::new(), MUTED),
        };
        let right = text(14, colour).pos(Pos::new(HPos::Right, VPos::Top));
        header.draw_text(&faults, &right, (width, 10))?;
        let right_w = header.estimate_text_size(&faults, &right)?.0 as i32;
        let mut about = row.source.clone();
        if let Some(data) = row.data
            && data.energy.seconds() > 0.0
        {
            let e = &data.energy;
            about.push_str(&format!(
                "  ·  {} mAh, {} Wh{}",
                Fixed(e.charge_mah(), 1),
                Fixed(e.energy_wh(), 2),
                if e.nominal() {
                    format!(
                        " (each frame counted as {} ms)",
                        (e.period_s() * 1e6).round() / 1000.0
                    )
                } else {
                    String::new()
                }
            ));
        }
        if let Some(info) = &row.info {
            about.push_str("  ·  ");
            about.push_str(info);
        }
        let style = text(14, MUTED);
        let fitted = fit(&header, &about, &style, width - x - right_w - 20)?;
        header.draw_text(&fitted, &style, (x, 10))?;
        let Some(data) = row.data else {
            let (w, h) = body.dim_in_pixel();
            let style = text(15, MUTED).pos(Pos::new(HPos::Center, VPos::Center));
            let message = row.empty.as_deref().unwrap_or("no data frames");
            body.draw_text(message, &style, (w as i32 / 2, h as i32 / 2))?;
            return Ok(());
        };
        let areas = body.split_evenly((1, PANELS));
        // The lines of the quantities this ESC's format carries (HW5's BEC and motor, V3's few).
        let panels: Vec<Panel> = self
            .panels
            .iter()
            .map(|panel| panel.carried_by(data.protocol))
            .collect();
        let mut captions = panels
            .iter()
            .zip(&areas)
            .map(|(panel, area)| Caption::new(area, panel))
            .collect::<Result<Vec<_>, _>>()?;
        if captions.iter().any(|c| c.x == 0) {
            captions.iter_mut().for_each(|c| c.x = 0);
        }
        // One caption height for the row, so that its panels line up.
        let caption_h = if captions.iter().any(|c| c.own_line) {
            2 * CAPTION_H - 4
        } else {
            CAPTION_H
        };
        for (p, (area, caption)) in areas.iter().zip(captions).enumerate() {
            let (top, chart) = area.split_vertically(caption_h);
            caption.draw(&top)?;
            self.draw_panel(&chart, &panels[p], self.ranges[p], data, row.offset, p == 0)?;
        }
        Ok(())
    }

    fn draw_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        panel: &Panel,
        (y_lo, y_hi): (f64, f64),
        data: &EscData,
        offset: f64,
        label_faults: bool,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let (t_lo, t_hi) = (self.time.lo, self.time.hi);
        let mut chart = ChartBuilder::on(area)
            .margin_right(14)
            .margin_top(4)
            .x_label_area_size(X_LABELS_H)
            .y_label_area_size(Y_LABELS_W)
            .build_cartesian_2d(t_lo..t_hi, y_lo..y_hi)?;
        let x_fmt = number_format(t_lo..t_hi);
        let y_fmt = number_format(y_lo..y_hi);
        let x_desc = if data.timed {
            "time (s)".to_string()
        } else {
            format!("frame index × {} (s)", data.period())
        };
        // As many time labels as fit side by side, at most TICKS.
        let plot_w = chart.plotting_area().dim_in_pixel().0.max(1);
        let label_w = [t_lo, t_hi]
            .iter()
            .map(|t| area.estimate_text_size(&x_fmt(t), &text(12, TEXT)))
            .collect::<Result<Vec<_>, _>>()?
            .into_iter()
            .map(|(w, _)| w + 16)
            .max()
            .unwrap_or(1);
        let x_ticks = (plot_w / label_w.max(1)).clamp(2, TICKS as u32) as usize;
        chart
            .configure_mesh()
            .x_labels(x_ticks)
            .y_labels(TICKS)
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .x_desc(x_desc)
            .y_desc(&panel.axis)
            .label_style(text(12, TEXT))
            .axis_desc_style(text(12, MUTED))
            .bold_line_style(GRID.stroke_width(1))
            .light_line_style(TRANSPARENT)
            .axis_style(AXIS.stroke_width(1))
            .draw()?;
        let per_px = (t_hi - t_lo) / f64::from(plot_w);
        // Fault spans under the lines, at least a pixel wide.
        let spans = pixel_spans(&data.spans, offset, per_px);
        chart.draw_series(
            spans
                .iter()
                .map(|&(a, b, _)| Rectangle::new([(a, y_lo), (b, y_hi)], FAULT.mix(0.16).filled())),
        )?;
        // The windows of check's findings under the lines, at least a pixel wide.
        chart.draw_series(data.shades.iter().map(|sh| {
            let a = sh.start - offset;
            let b = (sh.end - offset).max(a + per_px);
            Rectangle::new(
                [(a, y_lo), (b, y_hi)],
                shade_colour(sh.severity).mix(0.22).filled(),
            )
        }))?;
        if label_faults {
            let small = text(11, TEXT);
            for sh in &data.shades {
                let label = EmptyElement::at((sh.start - offset, y_lo))
                    + Text::new(format!("{} {}", sh.severity, sh.label), (3, -16), &small);
                chart.draw_series(std::iter::once(label))?;
            }
        }
        let columns = columns(data, offset, self.time, plot_w);
        for (i, &(quantity, _, colour)) in panel.lines.iter().enumerate() {
            // The first line of two is drawn wider, so that the second never hides it.
            let width = if panel.lines.len() > 1 && i == 0 {
                3
            } else {
                2
            };
            let style = colour.stroke_width(width);
            let pieces = paths(&columns, quantity)
                .into_iter()
                .flat_map(|p| cut_at_sharp_turns(p, |v| chart.backend_coord(v)))
                .collect::<Vec<_>>();
            for path in pieces {
                if path.len() == 1 {
                    chart.draw_series(std::iter::once(Circle::new(path[0], 2, colour.filled())))?;
                } else {
                    chart.draw_series(std::iter::once(PathElement::new(path, style)))?;
                }
            }
        }
        if label_faults {
            // Fault names at the top of their spans, left to right, on the first of three lines
            // where they overlap no other name (or not at all).
            let (px_range, _) = chart.plotting_area().get_pixel_range();
            let small = text(11, FAULT_TEXT);
            let mut free = [i32::MIN; LABEL_LINES];
            // Where each text was last put: the same names are not repeated close by.
            let mut seen: Vec<(String, i32)> = Vec::new();
            for &(a, _, bits) in &spans {
                let names = fault_names(data.protocol, bits);
                let (tw, th) = chart.plotting_area().estimate_text_size(&names, &small)?;
                let (tw, th) = (tw as i32, th as i32);
                let (px, _) = chart.backend_coord(&(a, y_hi));
                let left = (px + 3).min(px_range.end - tw - 3);
                let Some(line) = (0..LABEL_LINES).find(|&l| left >= free[l]) else {
                    continue;
                };
                let repeated = seen
                    .iter()
                    .any(|(text, x)| *text == names && left - x < 3 * tw);
                if left < px_range.start || repeated {
                    continue;
                }
                free[line] = left + tw + 8;
                seen.push((names.clone(), left));
                let (x, y) = (left - px, 3 + line as i32 * (th + 3));
                let label = EmptyElement::at((a, y_hi))
                    + Rectangle::new(
                        [(x - 2, y - 1), (x + tw + 2, y + th + 1)],
                        WHITE.mix(0.75).filled(),
                    )
                    + Text::new(names, (x, y), &small);
                chart.draw_series(std::iter::once(label))?;
            }
        }
        Ok(())
    }
}

/// A panel's caption: its name and the legend of its lines, over the plotting area; from the
/// panel's left edge if they need the room, the legend on a line of its own if they need more.
struct Caption {
    title: &'static str,
    title_w: i32,
    /// Legend entries: text, colour, text width.
    legend: Vec<(&'static str, RGBColor, i32)>,
    /// Where the caption starts.
    x: i32,
    /// Whether the legend has a line of its own.
    own_line: bool,
    /// The panel's width: legend entries past it are left out.
    width: i32,
}

impl Caption {
    fn new<DB: DrawingBackend>(
        area: &DrawingArea<DB, Shift>,
        panel: &Panel,
    ) -> Result<Caption, DrawingAreaErrorKind<DB::ErrorType>> {
        let panel_w = area.dim_in_pixel().0 as i32;
        let title_w = area.estimate_text_size(panel.title, &bold(14, TEXT))?.0 as i32;
        let mut legend = Vec::new();
        if panel.lines.len() > 1 {
            for &(_, name, colour) in &panel.lines {
                let w = area.estimate_text_size(name, &text(12, MUTED))?.0 as i32;
                legend.push((name, colour, w));
            }
        }
        let legend_w: i32 = legend.iter().map(|&(_, _, w)| w + 30).sum();
        let (x, own_line) = if Y_LABELS_W as i32 + title_w + 12 + legend_w <= panel_w {
            (Y_LABELS_W as i32, false)
        } else {
            (0, title_w + 12 + legend_w > panel_w)
        };
        Ok(Caption {
            title: panel.title,
            title_w,
            legend,
            x,
            own_line,
            width: panel_w,
        })
    }

    fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        area.draw_text(self.title, &bold(14, TEXT), (self.x, 2))?;
        let (mut x, y) = if self.own_line {
            (0, CAPTION_H as i32 - 4)
        } else {
            (self.x + self.title_w + 12, 0)
        };
        for &(name, colour, w) in &self.legend {
            if x + 20 + w > self.width {
                break;
            }
            area.draw(&Rectangle::new(
                [(x, y + 9), (x + 16, y + 12)],
                colour.filled(),
            ))?;
            area.draw_text(name, &text(12, MUTED), (x + 20, y + 4))?;
            x += w + 30;
        }
        Ok(())
    }
}

/// A text style of the embedded font.
fn text(size: u32, colour: RGBColor) -> TextStyle<'static> {
    styled(size, colour, FontStyle::Normal)
}

/// A bold text style of the embedded font.
fn bold(size: u32, colour: RGBColor) -> TextStyle<'static> {
    styled(size, colour, FontStyle::Bold)
}

fn styled(size: u32, colour: RGBColor, style: FontStyle) -> TextStyle<'static> {
    TextStyle {
        font: FontDesc::new(FontFamily::Name(FONT), f64::from(size), style),
        color: colour.to_backend_color(),
        pos: Pos::default(),
    }
}

/// `s`, cut with an ellipsis to fit `width` pixels.
fn fit<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: &str,
    style: &TextStyle,
    width: i32,
) -> Result<String, DrawingAreaErrorKind<DB::ErrorType>> {
    if area.estimate_text_size(s, style)?.0 as i32 <= width {
        return Ok(s.to_string());
    }
    let chars: Vec<char> = s.chars().collect();
    let (mut lo, mut hi) = (0, chars.len());
    while lo < hi {
        let mid = (lo + hi).div_ceil(2);
        let cut: String = chars[..mid].iter().collect::<String>() + "…";
        if area.estimate_text_size(&cut, style)?.0 as i32 <= width {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    Ok(chars[..lo].iter().collect::<String>() + "…")
}

/// Tick labels with as many decimals as the ticks plotters puts on `range` need: all alike.
fn number_format(range: std::ops::Range<f64>) -> impl Fn(&f64) -> String {
    let ticks = RangedCoordf64::from(range).key_points(TICKS);
    let exact = |d: i32| {
        let scale = 10f64.powi(d);
        ticks
            .iter()
            .all(|t| ((t * scale).round() - t * scale).abs() < 1e-6 * scale.max(1.0))
    };
    let decimals = (0..4).find(|&d| exact(d)).unwrap_or(4) as usize;
    move |v: &f64| {
        let s = format!("{v:.decimals$}");
        // No "-0" for a tick a rounding error below zero.
        match s.strip_prefix('-') {
            Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
            _ => s,
        }
    }
}

/// The value range of a panel over every row, padded.
fn value_range(panel: &Panel, rows: &[Row]) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for row in rows {
        let Some(data) = row.data else { continue };
        for cell in &data.buckets.cells {
            for &(q, _, _) in &panel.lines {
                if let Some([_, a, b, _]) = cell.values(q) {
                    lo = lo.min(a);
                    hi = hi.max(b);
                }
            }
        }
    }
    if lo > hi {
        (lo, hi) = (0.0, 1.0);
    }
    let pad = |lo: f64, hi: f64| {
        let p = (hi - lo) * 0.06;
        (lo - p, hi + p)
    };
    match panel.scale {
        Scale::Percent => pad(lo.min(0.0), hi.max(100.0)),
        Scale::FromZero => {
            let (lo, hi) = (lo.min(0.0), hi.max(0.0));
            let (a, b) = pad(lo, if hi - lo < 1.0 { lo + 1.0 } else { hi });
            (if lo == 0.0 { 0.0 } else { a }, b)
        }
        Scale::Auto(min_span) => {
            let mid = (lo + hi) / 2.0;
            let half = ((hi - lo) / 2.0).max(min_span / 2.0);
            pad(mid - half, mid + half)
        }
    }
}

/// The colour of a finding's window: amber for a warning, purple for a critical finding.
fn shade_colour(severity: hwfoc_io::check::Severity) -> RGBColor {
    match severity {
        hwfoc_io::check::Severity::Critical => CRITICAL,
        _ => WARNING,
    }
}

/// The fault spans of an ESC on the time axis, at least `per_px` wide, those that would touch
/// or overlap on the image merged (thousands of spans in one pixel would add up to solid red).
fn pixel_spans(spans: &[Span], offset: f64, per_px: f64) -> Vec<(f64, f64, hwfoc::Status)> {
    let mut out: Vec<(f64, f64, hwfoc::Status)> = Vec::new();
    for s in spans {
        let a = s.start - offset;
        let b = (s.end - offset).max(a + per_px);
        match out.last_mut() {
            Some(last) if a - last.1 < per_px => {
                last.1 = last.1.max(b);
                last.2 = hwfoc::Status(last.2.0 | s.bits.0);
            }
            _ => out.push((a, b, s.bits)),
        }
    }
    out
}

/// The buckets of an ESC merged into columns of pixels: x at the column's centre.
fn columns(data: &EscData, offset: f64, time: TimeAxis, plot_w: u32) -> Vec<(f64, Bucket)> {
    let b = &data.buckets;
    let (first, last) = data.clock.unwrap_or((b.origin, b.origin));
    let scale = f64::from(plot_w) / (time.hi - time.lo);
    let mut out: Vec<(i64, Bucket)> = Vec::new();
    for (i, cell) in b.cells.iter().enumerate() {
        if cell.frames == 0 {
            continue;
        }
        let c = (b.origin + (i as f64 + 0.5) * b.width).clamp(first, last);
        let col = (((c - offset - time.lo) * scale).floor() as i64).clamp(0, i64::from(plot_w) - 1);
        match out.last_mut() {
            Some((last_col, bucket)) if *last_col == col => bucket.merge(cell),
            _ => out.push((col, *cell)),
        }
    }
    out.into_iter()
        .map(|(col, bucket)| (time.lo + (col as f64 + 0.5) / scale, bucket))
        .collect()
}

/// The lines of one quantity through the columns: first, lowest, highest and last value of
/// each, broken at gaps and where the quantity has no value.
fn paths(columns: &[(f64, Bucket)], q: Shown) -> Vec<Vec<(f64, f64)>> {
    let mut paths = Vec::new();
    let mut path: Vec<(f64, f64)> = Vec::new();
    for (x, b) in columns {
        let values = b.values(q);
        if (b.gap_before || values.is_none()) && !path.is_empty() {
            paths.push(std::mem::take(&mut path));
        }
        let Some(values) = values else {
            continue;
        };
        for v in values {
            let point = (*x, v);
            if path.last() != Some(&point) {
                path.push(point);
            }
        }
    }
    if !path.is_empty() {
        paths.push(path);
    }
    paths
}

/// `path` cut where it nearly turns back on itself on the image (`px` gives a point's pixel),
/// each piece ending at the turn. plotters' bitmap backend joins the segments of a wide line
/// by mitring without a limit, so at such a turn (a one-frame spike: up and straight down) the
/// mitre ran far past the point, through the panel's header or axis labels to the image's edge;
/// SVG renderers limit mitres to 4 line widths, the limit taken here: a turn whose inner angle
/// is under 29 degrees (its cosine over 0.875).
fn cut_at_sharp_turns(
    path: Vec<(f64, f64)>,
    px: impl Fn(&(f64, f64)) -> (i32, i32),
) -> Vec<Vec<(f64, f64)>> {
    if path.len() < 3 {
        return vec![path];
    }
    let pixels: Vec<(f64, f64)> = path
        .iter()
        .map(|p| {
            let (x, y) = px(p);
            (f64::from(x), f64::from(y))
        })
        .collect();
    let mut pieces = Vec::new();
    let mut start = 0;
    for i in 1..path.len() - 1 {
        let (a, b, c) = (pixels[i - 1], pixels[i], pixels[i + 1]);
        let (u, v) = ((b.0 - a.0, b.1 - a.1), (c.0 - b.0, c.1 - b.1));
        let lengths = u.0.hypot(u.1) * v.0.hypot(v.1);
        if lengths > 0.0 && (u.0 * v.0 + u.1 * v.1) / lengths < -0.875 {
            pieces.push(path[start..=i].to_vec());
            start = i;
        }
    }
    pieces.push(path[start..].to_vec());
    pieces
}

/// The fault names of a fault word of `protocol`, joined.
fn fault_names(protocol: Option<hwfoc::Protocol>, status: hwfoc::Status) -> String {
    protocol
        .unwrap_or(hwfoc::Protocol::HwFoc)
        .fault_names(status)
        .collect::<Vec<_>>()
        .join(", ")
}

/// The header's fault text, and its colour: an only episode with its times as the summary
/// gives them ([`hwfoc_io::summary::Episode::when`]), several by their count.
fn fault_summary(data: &EscData, wall: bool) -> (String, RGBColor) {
    let Some(first) = data.first_episode.as_ref() else {
        return ("no faults".to_string(), OK_TEXT);
    };
    let bits = data.spans.iter().fold(0u16, |acc, s| acc | s.bits.0);
    let names = fault_names(data.protocol, hwfoc::Status(bits));
    let text = if data.episodes == 1 {
        format!(
            "fault: {names}, {}{}",
            first.when(wall),
            if first.ongoing { " (to the end)" } else { "" }
        )
    } else {
        format!("faults: {names} ({} episodes)", data.episodes)
    };
    (text, FAULT_TEXT)
}

/// How an ESC's source is named: its input, and its stream when that says more.
fn source_name(sources: &Sources, esc: usize) -> String {
    let e = &sources.esc_table()[esc];
    let (input, port) = (&sources.names()[e.input], &e.key.port);
    if port == input || port.is_empty() {
        input.clone()
    } else {
        format!("{input}: {port}")
    }
}

/// Why there is nothing to plot at all.
fn nothing_message(collector: &Collector, sources: &Sources, shown: &[usize]) -> String {
    let window = collector.window();
    let times = shown
        .iter()
        .filter_map(|&i| collector.esc(i).and_then(|d| d.times))
        .fold(None, |acc: Option<(f64, f64)>, (a, b)| {
            Some(acc.map_or((a, b), |(x, y)| (x.min(a), y.max(b))))
        });
    if let (true, Some((first, last))) = (window.is_limited(), times) {
        return format!(
            "no frame in the time window: {}",
            time::span_text(first, last, sources.clock() == Some(Clock::Wall))
        );
    }
    let names = sources.names().join(", ");
    if shown
        .iter()
        .any(|&i| collector.esc(i).is_some_and(|d| d.frames > 0))
    {
        format!("{names}: no data frames")
    } else {
        let mut reasons: Vec<String> = shown.iter().map(|&i| no_frames(sources, i)).collect();
        reasons.dedup();
        match reasons.as_slice() {
            [one] => format!("{names}: {one}"),
            _ => shown
                .iter()
                .map(|&i| {
                    format!(
                        "{}: {}",
                        hwfoc_io::summary::esc_label(sources, i),
                        no_frames(sources, i)
                    )
                })
                .collect::<Vec<_>>()
                .join("; "),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_panels_and_their_lines() {
        type Lines = Vec<(&'static str, RGBColor)>;
        let got: Vec<(&str, String, Lines)> = panels()
            .iter()
            .map(|p| {
                let lines = p.lines.iter().map(|&(_, legend, c)| (legend, c)).collect();
                (p.title, p.axis.clone(), lines)
            })
            .collect();
        let want: Vec<(&str, String, Lines)> = vec![
            (
                "Throttle",
                "throttle (%)".into(),
                vec![("input", BLUE), ("output", ORANGE)],
            ),
            ("Speed", "speed (rpm)".into(), vec![("rpm", GREEN)]),
            (
                "Current",
                "current (A)".into(),
                vec![("input", BLUE), ("phase", ORANGE), ("BEC", GREEN)],
            ),
            ("Power", "power (W)".into(), vec![("input", GREEN)]),
            (
                "Voltage",
                "voltage (V)".into(),
                vec![("input", PURPLE), ("BEC", ORANGE)],
            ),
            (
                "Temperature",
                "temperature (°C)".into(),
                vec![
                    ("MOSFET", RED),
                    ("capacitor", TEAL),
                    ("motor", ORANGE),
                    ("BEC", BLUE),
                ],
            ),
        ];
        assert_eq!(got, want);
        // An ESC's row has the lines its format carries: HW-FOC's as before HW5's were added,
        // HW5's without phase current or capacitor, every line before a frame told the format.
        let legends = |p: Option<hwfoc::Protocol>| -> Vec<Vec<&str>> {
            panels()
                .iter()
                .map(|panel| panel.carried_by(p).lines.iter().map(|l| l.1).collect())
                .collect()
        };
        assert_eq!(
            legends(Some(hwfoc::Protocol::HwFoc)),
            [
                vec!["input", "output"],
                vec!["rpm"],
                vec!["input", "phase"],
                vec!["input"],
                vec!["input"],
                vec!["MOSFET", "capacitor"],
            ]
        );
        assert_eq!(
            legends(Some(hwfoc::Protocol::Hw5)),
            [
                vec!["input"],
                vec!["rpm"],
                vec!["input", "BEC"],
                vec!["input"],
                vec!["input", "BEC"],
                vec!["MOSFET", "motor", "BEC"],
            ]
        );
        assert_eq!(legends(None)[5].len(), 4);
    }

    #[test]
    fn number_format_fits_the_range() {
        assert_eq!(number_format(0.0..100.0)(&25.0), "25");
        assert_eq!(number_format(23.0..25.0)(&24.5), "24.5");
        assert_eq!(number_format(23.0..25.0)(&24.0), "24.0");
        assert_eq!(number_format(-0.1..0.1)(&-0.0000001), "0.00");
    }

    #[test]
    fn paths_break_at_gaps_and_missing_values() {
        let frame = |throttle: u16, mos: u8| {
            let f = hwfoc::foc::DataFrame {
                throttle_in_raw: throttle,
                mos_adc: mos,
                ..Default::default()
            };
            crate::shown::values(&hwfoc_io::record::Record::new(
                None,
                0,
                &f.into(),
                &hwfoc::Settings::DEFAULT,
            ))
        };
        let mut a = Bucket::EMPTY;
        for t in [512, 0, 1024, 512] {
            a.add(&frame(t, 206), false);
        }
        let mut gap = Bucket::EMPTY;
        gap.add(&frame(512, 206), true);
        let mut missing = Bucket::EMPTY;
        missing.add(&frame(512, 250), false);
        let cols = [(0.0, a), (1.0, a), (2.0, gap), (3.0, missing), (4.0, a)];
        // Throttle: broken at the gap only; its points are first, min, max, last.
        let p = paths(&cols, Shown::Carried(hwfoc::Quantity::ThrottleIn));
        assert_eq!(p.len(), 2);
        assert_eq!(
            p[0],
            [
                (0.0, 50.0),
                (0.0, 0.0),
                (0.0, 100.0),
                (0.0, 50.0),
                (1.0, 50.0),
                (1.0, 0.0),
                (1.0, 100.0),
                (1.0, 50.0)
            ]
        );
        assert_eq!(p[1][0], (2.0, 50.0));
        // Temperature: broken at the gap and where out of range.
        let p = paths(&cols, Shown::Carried(Quantity::MosTemp));
        assert_eq!(p.len(), 3);
        assert_eq!(p[2], [(4.0, 28.0)]);
    }
}
