//! The full-screen dashboard (ratatui over crossterm).
//!
//! From top to bottom: a title line (time, recording, pause), one row per ESC with live values
//! and peaks, then the selected ESC's charts of the last minute beside the alarm log, and a line
//! of keys. Warning cells are yellow, critical ones red. It redraws at most every
//! [`FRAME_EVERY`] while frames arrive (so a frame is on the screen well within 100 ms) and
//! every [`IDLE_EVERY`] otherwise (ages tick on). The terminal is restored however it ends:
//! `q`, Ctrl-C, SIGTERM, `--duration`, an error, or a panic (ratatui's hook).

use std::collections::VecDeque;
use std::thread;
use std::time::{Duration, Instant};

use ratatui::DefaultTerminal;
use ratatui::Frame;
use ratatui::crossterm::event::{self, Event, KeyCode, KeyEvent, KeyEventKind, KeyModifiers};
use ratatui::layout::{Alignment, Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style, Stylize};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{
    Axis, Block, Borders, Cell, Chart, Clear, Dataset, GraphType, List, ListItem, Paragraph, Row,
    Table, TableState,
};

use super::alarms::{Change, Level};
use super::feed::Msg;
use super::fleet::{EscView, HISTORY_S, Link, LogEntry, total_energy, total_power_w};
use super::{Session, number, reading};
use crate::error::CliError;
use crate::shown::{Measure, Shown};
use hwfoc::Quantity;
use hwfoc::format::InfoValue;
use hwfoc::telemetry::Info;
use hwfoc_io::Escaped;
use hwfoc_io::Fixed;
use hwfoc_io::energy::Energy;

/// Shortest time between redraws while frames arrive.
const FRAME_EVERY: Duration = Duration::from_millis(50);
/// Redraw at least this often.
const IDLE_EVERY: Duration = Duration::from_millis(250);
/// Terminals at least this wide show peaks beside the live values and the log beside the charts.
const WIDE: u16 = 140;

/// What the screen shows: live, or a copy frozen by `p`.
#[derive(Clone, Copy)]
struct View<'a> {
    escs: &'a [EscView],
    log: &'a VecDeque<LogEntry>,
    now: f64,
    /// Highest power of all ESCs together, W.
    peak_total_w: Option<f64>,
}

/// The copy the display shows while paused.
struct Frozen {
    escs: Vec<EscView>,
    log: VecDeque<LogEntry>,
    now: f64,
    peak_total_w: Option<f64>,
}

/// The dashboard's own state.
struct Ui {
    selected: usize,
    frozen: Option<Frozen>,
    help: bool,
    quit: bool,
}

/// Runs the dashboard until `q`, Ctrl-C, SIGTERM or the end of `--duration`.
pub fn run(session: &mut Session) -> Result<(), CliError> {
    let mut terminal = ratatui::try_init().map_err(|source| CliError::Terminal { source })?;
    let result = main_loop(session, &mut terminal);
    let restored = ratatui::try_restore().map_err(|source| CliError::Terminal { source });
    result.and(restored)
}

fn main_loop(session: &mut Session, terminal: &mut DefaultTerminal) -> Result<(), CliError> {
    let tx = session.sender();
    // Keys, resizes: read in a thread of their own, delivered with the telemetry.
    thread::Builder::new()
        .name("keyboard".into())
        .spawn(move || {
            while let Ok(event) = event::read() {
                if tx.send(Msg::Term(event)).is_err() {
                    break;
                }
            }
        })
        .map_err(|source| CliError::Terminal { source })?;
    let mut ui = Ui {
        selected: 0,
        frozen: None,
        help: false,
        quit: false,
    };
    let mut last_draw: Option<Instant> = None;
    let mut dirty = true;
    // When the next redraw is due: soon after the last one while something changed or frames
    // wait to be shown, otherwise only to let ages tick on.
    let due = |last_draw: Option<Instant>, busy: bool| match last_draw {
        None => Instant::now(),
        Some(t) if busy => t + FRAME_EVERY,
        Some(t) => t + IDLE_EVERY,
    };
    while !ui.quit && !session.should_stop() {
        let now = Instant::now();
        let due_at = due(last_draw, dirty || session.perf.has_pending());
        let wait = due_at.saturating_duration_since(now);
        let events = if session.perf.has_pending() {
            // Frames are waiting for the next redraw anyway: take in everything that comes
            // until then in one go, rather than waking for every chunk of every port (a key
            // waits at most one redraw interval).
            std::thread::sleep(wait);
            session.pump(Duration::ZERO)?
        } else {
            session.pump(wait)?
        };
        for event in events {
            dirty |= handle(&mut ui, session, event);
        }
        let due_at = due(last_draw, dirty || session.perf.has_pending());
        if Instant::now() >= due_at && !ui.quit {
            let view = match &ui.frozen {
                Some(f) => View {
                    escs: &f.escs,
                    log: &f.log,
                    now: f.now,
                    peak_total_w: f.peak_total_w,
                },
                None => View {
                    escs: &session.fleet.escs,
                    log: &session.fleet.log,
                    now: session.now(),
                    peak_total_w: session.fleet.peak_total_w,
                },
            };
            let started = Instant::now();
            terminal
                .draw(|frame| draw(frame, session, &ui, view))
                .map_err(|source| CliError::Terminal { source })?;
            session.perf.drawn(started, Instant::now());
            last_draw = Some(started);
            dirty = false;
        }
    }
    Ok(())
}

/// Acts on a key or a resize; returns whether the screen should be redrawn soon.
fn handle(ui: &mut Ui, session: &mut Session, event: Event) -> bool {
    let Event::Key(KeyEvent {
        code,
        modifiers,
        kind,
        ..
    }) = event
    else {
        // A resize (or focus, paste): redraw.
        return true;
    };
    if kind == KeyEventKind::Release {
        return false;
    }
    let n = session.fleet.escs.len().max(1);
    match code {
        KeyCode::Char('c') if modifiers.contains(KeyModifiers::CONTROL) => ui.quit = true,
        KeyCode::Char('q') => ui.quit = true,
        KeyCode::Esc if ui.help => ui.help = false,
        KeyCode::Esc => ui.quit = true,
        KeyCode::Char('?') | KeyCode::Char('h') | KeyCode::F(1) => ui.help = !ui.help,
        KeyCode::Up | KeyCode::Char('k') | KeyCode::BackTab => {
            ui.selected = (ui.selected + n - 1) % n;
        }
        KeyCode::Down | KeyCode::Char('j') | KeyCode::Tab => {
            ui.selected = (ui.selected + 1) % n;
        }
        KeyCode::Home => ui.selected = 0,
        KeyCode::End => ui.selected = n.saturating_sub(1),
        KeyCode::Char(d @ '0'..='9') => {
            let i = d as usize - '0' as usize;
            if i < n {
                ui.selected = i;
            }
        }
        KeyCode::Char('p') | KeyCode::Char(' ') => {
            ui.frozen = match ui.frozen {
                Some(_) => None,
                None => Some(Frozen {
                    escs: session.fleet.escs.clone(),
                    log: session.fleet.log.clone(),
                    now: session.now(),
                    peak_total_w: session.fleet.peak_total_w,
                }),
            };
        }
        KeyCode::Char('c') => {
            session.fleet.reset_peaks();
            session.notice = Some("peaks reset".into());
        }
        KeyCode::Char('r') => session.toggle_recording(),
        _ => return false,
    }
    true
}

fn draw(frame: &mut Frame, session: &Session, ui: &Ui, view: View<'_>) {
    let n = view.escs.len();
    let table_height = (n as u16 + 3).min(frame.area().height.saturating_sub(6).max(4));
    let [title, table, bottom, keys] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Length(table_height),
        Constraint::Min(0),
        Constraint::Length(1),
    ])
    .areas(frame.area());
    draw_title(frame, title, session, ui, view);
    draw_table(frame, table, ui, view);
    // Side by side on a wide terminal; the log under the charts on a narrow one.
    let [detail, log] = if frame.area().width >= WIDE {
        Layout::horizontal([Constraint::Percentage(68), Constraint::Percentage(32)]).areas(bottom)
    } else {
        Layout::vertical([Constraint::Percentage(65), Constraint::Percentage(35)]).areas(bottom)
    };
    if let Some(esc) = view.escs.get(ui.selected) {
        draw_detail(frame, detail, ui.selected, esc, view.now);
    }
    draw_log(frame, log, view);
    frame.render_widget(
        Paragraph::new(Line::from(vec![
            " ↑↓ ".bold(),
            "select  ".into(),
            "p ".bold(),
            "pause  ".into(),
            "c ".bold(),
            "reset peaks  ".into(),
            "r ".bold(),
            "record  ".into(),
            "? ".bold(),
            "help  ".into(),
            "q ".bold(),
            "quit".into(),
        ]))
        .style(Style::new().fg(Color::Gray)),
        keys,
    );
    if ui.help {
        draw_help(frame, session);
    }
}

fn draw_title(frame: &mut Frame, area: Rect, session: &Session, ui: &Ui, view: View<'_>) {
    let n = view.escs.len();
    // What matters most first: a narrow terminal cuts the line on the right.
    let mut spans = vec![" hwfoc monitor ".bold().reversed()];
    if let Some(recorder) = &session.recorder {
        spans.push("  ● REC ".red().bold());
        spans.push(super::display_path(recorder.current()).into());
    }
    if ui.frozen.is_some() {
        spans.push("  PAUSED (p resumes)".yellow().bold());
    }
    if let Some(notice) = &session.notice {
        spans.push(format!("  {}", Escaped(notice)).cyan());
    }
    // The latest warning the streams found (two CAN ESCs on one throttle channel): it stays
    // until the set-up is mended and the monitor started again.
    if let Some(warning) = session.found.iter().rev().find(|n| n.is_warning()) {
        spans.push(format!("  {warning}").yellow().bold());
    }
    spans.push(
        format!(
            "  {n} ESC{}{}  ",
            if n == 1 { "" } else { "s" },
            if session.simulated { " (virtual)" } else { "" }
        )
        .into(),
    );
    spans.push(super::iso8601(view.now, false).into());
    spans.push(format!("  {} frames", session.fleet.frames).dark_gray());
    frame.render_widget(Paragraph::new(Line::from(spans)), area);
}

/// Style of a cell at an alarm level.
fn level_style(level: Option<Level>) -> Style {
    match level {
        Some(Level::Critical) => Style::new().fg(Color::White).bg(Color::Red).bold(),
        Some(Level::Warning) => Style::new().fg(Color::Black).bg(Color::Yellow),
        None => Style::new(),
    }
}

/// A live value with its peak beside it, dimmed: `20.3 ↑25.1` (the value alone when `compact`).
fn with_peak(
    live: String,
    arrow: &str,
    peak: Option<f32>,
    decimals: usize,
    compact: bool,
) -> Line<'static> {
    let mut spans = vec![Span::raw(live)];
    if let Some(p) = peak.filter(|_| !compact) {
        spans.push(Span::styled(
            format!(" {arrow}{}", number(p, decimals)),
            Style::new().fg(Color::DarkGray),
        ));
    }
    Line::from(spans)
}

fn draw_table(frame: &mut Frame, area: Rect, ui: &Ui, view: View<'_>) {
    let total_energy = total_energy(view.escs);
    let total_power = total_power_w(view.escs);
    let compact = area.width < WIDE;
    let titles = if compact {
        [
            "ESC", "Name", "Thr %", "RPM", "V", "A", "Ph A", "MOS", "CAP", "fr/s", "l/d/crc",
            "age", "Faults",
        ]
    } else {
        [
            "ESC",
            "Name",
            "Thr in/out %",
            "RPM  ↑max",
            "V  ↓min",
            "A  ↑max",
            "Phase A ↑max",
            "MOS °C ↑max",
            "CAP °C ↑max",
            "fr/s",
            "lost dup crc",
            "age s",
            "Faults and alarms",
        ]
    };
    let header = Row::new(titles).style(Style::new().bold().underlined());
    let with_peak = |live, arrow, peak, decimals| with_peak(live, arrow, peak, decimals, compact);
    let rows = view.escs.iter().enumerate().map(|(i, esc)| {
        let a = &esc.alarms;
        let p = &esc.peaks;
        let name = Cell::from(Escaped(esc.title()).to_string());
        let (values, faults): (Vec<Cell>, Cell) = match (&esc.link, &esc.last) {
            (Link::Down { since, .. }, _) => (
                vec![Cell::from(""); 6],
                Cell::from(format!("disconnected {:.0} s", view.now - since))
                    .style(level_style(Some(Level::Critical))),
            ),
            (Link::Up, None) => (
                vec![Cell::from(""); 6],
                Cell::from(match esc.trying {
                    Some(baud) => format!("finding the baud rate: trying {baud}"),
                    None => esc.waiting().to_string(),
                }),
            ),
            (Link::Up, Some(r)) => {
                let temp = |t: Option<f32>| t.map_or("-".to_string(), |t| number(t, 0));
                (
                    vec![
                        Cell::from(format!(
                            "{}/{}",
                            reading(r.throttle_in_pct, 0),
                            reading(r.throttle_out_pct, 0)
                        )),
                        Cell::from(with_peak(reading(r.rpm, 0), "↑", p.rpm, 0)),
                        Cell::from(with_peak(reading(r.voltage_v, 1), "↓", p.min_voltage_v, 1))
                            .style(level_style(a.voltage.level())),
                        Cell::from(with_peak(reading(r.current_a, 1), "↑", p.current_a, 1)),
                        Cell::from(with_peak(
                            reading(r.phase_current_a, 1),
                            "↑",
                            p.phase_current_a,
                            1,
                        )),
                        Cell::from(with_peak(temp(r.mos_temp_c), "↑", p.mos_temp_c, 0))
                            .style(level_style(a.mos.level())),
                    ],
                    alarm_cell(esc),
                )
            }
        };
        let cap = match &esc.last {
            Some(r) if esc.link == Link::Up => Cell::from(with_peak(
                r.cap_temp_c.map_or("-".into(), |t| number(t, 0)),
                "↑",
                p.cap_temp_c,
                0,
            ))
            .style(level_style(a.cap.level())),
            _ => Cell::from(""),
        };
        let stats = &esc.stats;
        let sep = if compact { "/" } else { " " };
        let link = format!(
            "{}{sep}{}{sep}{}",
            stats.lost_packets(),
            stats.duplicate_packets(),
            stats.checksum_failures()
        );
        let age = esc
            .age(view.now)
            .map_or("-".to_string(), |a| format!("{a:.1}"));
        let mut cells = vec![Cell::from(format!("{i}")), name];
        cells.extend(values);
        cells.push(cap);
        cells.push(Cell::from(format!("{:.1}", esc.frame_rate(view.now))));
        cells.push(Cell::from(link));
        cells.push(Cell::from(age).style(level_style(a.stale.level())));
        cells.push(faults);
        Row::new(cells)
    });
    let widths: [u16; 11] = if compact {
        [7, 6, 5, 5, 5, 3, 3, 4, 7, 4, 0]
    } else {
        [12, 12, 11, 11, 12, 11, 11, 5, 12, 5, 0]
    };
    let widths = [Constraint::Length(3), Constraint::Min(8)]
        .into_iter()
        .chain(widths[..10].iter().map(|&w| Constraint::Length(w)))
        .chain([Constraint::Fill(2)]);
    let total = energy_line(total_power, view.peak_total_w, &total_energy, "all ESCs");
    let table = Table::new(rows, widths)
        .header(header)
        .block(
            Block::new()
                .borders(Borders::TOP | Borders::BOTTOM)
                .title_bottom(total),
        )
        .row_highlight_style(Style::new().bg(Color::DarkGray))
        .highlight_symbol("▶")
        .column_spacing(1);
    let mut state = TableState::default().with_selected(Some(ui.selected));
    frame.render_stateful_widget(table, area, &mut state);
}

/// The active faults and alarms of an ESC by name, coloured by level.
fn alarm_cell(esc: &EscView) -> Cell<'static> {
    let active = esc.alarms.active();
    if active.is_empty() {
        return Cell::from("ok".green());
    }
    let worst = active.first().map(|(_, l)| *l);
    let names: Vec<&str> = active.iter().map(|(k, _)| k.name()).collect();
    Cell::from(names.join(" ")).style(level_style(worst))
}

/// The device line of a format whose info frame is adopted (V4's scales): its format, its
/// fields as its description names them, and whether they were taken (two identical copies).
fn adopted_info_line(info: &Info, adopted: bool) -> String {
    let fields: Vec<String> = info
        .fields()
        .map(|(key, value)| match value {
            InfoValue::Text(text) => format!("{key} {}", Escaped(text)),
            InfoValue::Number(n) => format!("{key} {n}"),
        })
        .collect();
    let state = if adopted {
        "adopted"
    } else {
        "not adopted yet (two identical copies needed)"
    };
    format!(
        "{} info: {} · {state}",
        info.protocol().title(),
        fields.join(" · ")
    )
}

fn draw_detail(frame: &mut Frame, area: Rect, index: usize, esc: &EscView, now: f64) {
    let hw5 = esc.protocol() == Some(hwfoc::Protocol::Hw5);
    let can = esc.protocol().is_some_and(hwfoc::Protocol::is_can);
    let info = match &esc.info {
        // A format whose info frame is adopted (V4's scales): its fields, and whether they were
        // taken (two identical copies).
        Some(info) if info.protocol().description().adopted_info.is_some() => {
            adopted_info_line(info, esc.stats.adopted_info().is_some())
        }
        // HW5 sends no device information: its BEC and motor instead.
        None if hw5 => {
            let r = esc.last.as_ref();
            let temp =
                |t: Option<f32>| t.map_or("-".to_string(), |t| format!("{}°C", number(t, 0)));
            format!(
                "BEC {} V {} A {} · motor {}",
                reading(r.and_then(|r| r.bec_voltage_v), 1),
                reading(r.and_then(|r| r.bec_current_a), 1),
                temp(r.and_then(|r| r.bec_temp_c)),
                temp(r.and_then(|r| r.motor_temp_c))
            )
        }
        // A CAN ESC: its node, its direction (a Hobbywing ESC's status bit 14), the ages of
        // the slower messages' values.
        None if can => {
            let r = esc.last.as_ref();
            let age = |a: Option<u32>| a.map_or("-".to_string(), |a| format!("{a} ms"));
            let direction = match r.and_then(|r| r.status) {
                Some(s) if s.0 & hwfoc::dronecan::StatusMsg1::STATUS_CCW != 0 => "ccw",
                Some(_) => "cw",
                None => "-",
            };
            format!(
                "CAN node {} · direction {direction} · StatusMsg2 age {} · StatusMsg3 age {} · status word {}",
                r.and_then(|r| r.node)
                    .map_or("-".to_string(), |n| n.to_string()),
                age(r.and_then(|r| r.msg2_age_ms)),
                age(r.and_then(|r| r.msg3_age_ms)),
                r.and_then(|r| r.status)
                    .map_or("-".to_string(), |s| format!("0x{:04X}", s.0)),
            )
        }
        Some(info) => Escaped(format_args!(
            "{} · hw {} · fw {} · id {}",
            info.product(),
            info.hardware(),
            info.firmware(),
            info.id()
        ))
        .to_string(),
        None => "no device information yet (sent while idle)".to_string(),
    };
    let cells = match (esc.cells, esc.cells_detected) {
        (Some(c), true) => format!("{c}S battery (detected; set --battery-cells)"),
        (Some(c), false) => format!("{c}S battery"),
        (None, _) => "battery cells unknown".to_string(),
    };
    let stats = &esc.stats;
    let block = Block::bordered().title(Line::from(vec![
        format!(" esc{index} ").bold(),
        format!("{} ", Escaped(esc.title())).into(),
        format!("· {} ", esc.rate_text()).dark_gray(),
    ]));
    let inner = block.inner(area);
    frame.render_widget(block, area);
    let [text, charts] = Layout::vertical([Constraint::Length(3), Constraint::Min(0)]).areas(inner);
    frame.render_widget(
        Paragraph::new(vec![
            energy_line(esc.power_w(), esc.energy.peak_w(), &esc.energy, "this ESC"),
            Line::from(info),
            Line::from(format!(
                "{cells} · {} frames · {} bytes, {} skipped · {}",
                stats.frames(),
                stats.bytes(),
                stats.bytes_skipped() + esc.discarded,
                esc.link_text()
            ))
            .dark_gray(),
        ]),
        text,
    );
    if charts.height < 2 * MIN_CHART_HEIGHT {
        draw_sparklines(frame, charts, esc, now);
        return;
    }
    let [top, low] = Layout::vertical([Constraint::Fill(1); 2]).areas(charts);
    // Room between the charts side by side, so that one's last x label ("now") and the next
    // one's y labels never run together.
    let beside = |area| {
        Layout::horizontal([Constraint::Fill(1); 2])
            .spacing(CHART_GAP)
            .areas(area)
    };
    let [rpm_area, current_area] = beside(top);
    let [volt_area, temp_area] = beside(low);
    // Two braille dots per cell across: more points than that cannot show, so each column of
    // dots gets the lowest and highest value that fell in it (spikes stay visible).
    let columns = usize::from(rpm_area.width).max(1) * 2;
    let areas = [rpm_area, current_area, volt_area, temp_area];
    for (measure, area) in CHARTS.into_iter().zip(areas) {
        let series: Vec<(&str, Color, Points)> = measure
            .shown()
            .filter(|&q| esc.carries(q))
            .map(|q| {
                let points = esc
                    .history
                    .iter()
                    .filter_map(|s| s.get(q).map(|v| (s.t - now, f64::from(v))));
                (q.short(), colour(q), envelope(points, columns))
            })
            .collect();
        let lines: Vec<Series> = series
            .iter()
            .map(|(name, color, data)| (*name, *color, data.as_slice()))
            .collect();
        chart(
            frame,
            area,
            &chart_title(measure),
            &lines,
            from_zero(measure),
        );
    }
}

/// The measures charted for the selected ESC, left to right and top to bottom (and as
/// sparklines where the charts do not fit).
const CHARTS: [Measure; 4] = [
    Measure::Speed,
    Measure::Current,
    Measure::Voltage,
    Measure::Temperature,
];

/// A chart's title: `RPM`, `Current A`, `Voltage V`, `Temperature °C`.
fn chart_title(measure: Measure) -> String {
    match measure {
        Measure::Speed => "RPM".to_string(),
        m => format!("{} {}", m.title(), m.unit()),
    }
}

/// Whether a chart of `measure` starts from zero (speeds and currents) or spans its values.
fn from_zero(measure: Measure) -> bool {
    matches!(measure, Measure::Speed | Measure::Current)
}

/// The colour of a quantity's line.
fn colour(q: Shown) -> Color {
    match q {
        Shown::Carried(Quantity::Rpm) => Color::Cyan,
        Shown::Carried(Quantity::Current) => Color::Yellow,
        Shown::Carried(Quantity::PhaseCurrent) => Color::Magenta,
        Shown::Carried(Quantity::Voltage) => Color::Green,
        Shown::Carried(Quantity::MosTemp) => Color::Red,
        Shown::Carried(Quantity::CapTemp) => Color::LightBlue,
        // HW5's, each apart from the others of its chart.
        Shown::Carried(Quantity::BecCurrent | Quantity::BecVoltage) => Color::LightCyan,
        Shown::Carried(Quantity::MotorTemp) => Color::LightMagenta,
        Shown::Carried(Quantity::BecTemp) => Color::LightCyan,
        _ => Color::Gray,
    }
}

/// `power 480 W (peak 1210 W) · used 312.5 mAh · 7.41 Wh`, and what it is of.
fn energy_line(
    power_w: Option<f64>,
    peak_w: Option<f64>,
    energy: &Energy,
    of: &str,
) -> Line<'static> {
    let w = |p: Option<f64>| p.map_or("-".to_string(), |p| format!("{} W", Fixed(p, 0)));
    Line::from(vec![
        "power ".dark_gray(),
        w(power_w).bold(),
        format!(" (peak {})", w(peak_w)).dark_gray(),
        " · used ".dark_gray(),
        format!("{} mAh", Fixed(energy.charge_mah(), 1)).bold(),
        " · ".dark_gray(),
        format!("{} Wh", Fixed(energy.energy_wh(), 2)).bold(),
        format!("  {of}, since start or c").dark_gray(),
    ])
}

/// The rows of a chart at the least: its title, three rows of data, the x axis and its labels.
const MIN_CHART_HEIGHT: u16 = 6;
/// Columns between two charts side by side.
const CHART_GAP: u16 = 3;
/// The eight heights of a sparkline column.
const BARS: [char; 8] = ['▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];

/// The last minute of `points` (seconds before now, value) as `width` characters of a
/// sparkline: each column the highest value that fell in it, scaled from the lowest to the
/// highest of all (from zero when `from_zero`); a column without data is a space.
fn sparkline(points: &[(f64, f64)], width: usize, from_zero: bool) -> String {
    if width == 0 {
        return String::new();
    }
    let mut columns: Vec<Option<f64>> = vec![None; width];
    for &(t, v) in points {
        if !v.is_finite() {
            continue;
        }
        let c = ((t + HISTORY_S) / HISTORY_S * width as f64).floor();
        if c >= 0.0 {
            let slot = &mut columns[(c as usize).min(width - 1)];
            *slot = Some(slot.map_or(v, |s: f64| s.max(v)));
        }
    }
    let values = columns.iter().flatten();
    let lo = values.clone().fold(f64::INFINITY, |a, &b| a.min(b));
    let hi = values.fold(f64::NEG_INFINITY, |a, &b| a.max(b));
    let lo = if from_zero { lo.min(0.0) } else { lo };
    columns
        .iter()
        .map(|c| match c {
            None => ' ',
            Some(v) if hi > lo => {
                let i = ((v - lo) / (hi - lo) * 7.0).round() as usize;
                BARS[i.min(7)]
            }
            Some(_) => BARS[0],
        })
        .collect()
}

/// A sparkline: its label, its quantity, the decimals and unit of its latest value, and
/// whether it starts from zero.
type Sparkline = (String, Option<Shown>, usize, String, bool);

/// The sparklines: the first quantity of each chart.
fn sparklines() -> [Sparkline; CHARTS.len()] {
    CHARTS.map(|m| {
        let q = m.shown().next();
        let (name, decimals, unit) = match m {
            Measure::Speed => ("RPM".to_string(), 0, String::new()),
            Measure::Temperature => {
                let name = format!("{} temp", q.map_or("", Shown::short));
                (name, 0, format!(" {}", m.unit()))
            }
            m => (m.title().to_string(), 1, format!(" {}", m.unit())),
        };
        (name, q, decimals, unit, from_zero(m))
    })
}

/// Where the charts do not fit (a terminal of 24 rows): one sparkline row per quantity, as many
/// as there is room for, each with its latest value.
fn draw_sparklines(frame: &mut Frame, area: Rect, esc: &EscView, now: f64) {
    let rows = sparklines();
    let label_width = 9;
    let value_width = 10;
    let width = usize::from(area.width).saturating_sub(label_width + value_width + 1);
    let lines: Vec<Line> = rows
        .iter()
        .take(usize::from(area.height))
        .map(|(name, q, decimals, unit, from_zero)| {
            let pick = |s: &super::fleet::Sample| q.and_then(|q| s.get(q));
            let points: Vec<(f64, f64)> = esc
                .history
                .iter()
                .filter_map(|s| pick(s).map(|v| (s.t - now, f64::from(v))))
                .collect();
            let latest = esc
                .history
                .back()
                .and_then(pick)
                .map_or("-".to_string(), |v| {
                    format!("{}{unit}", number(v, *decimals))
                });
            let color = q.map_or(Color::Gray, colour);
            Line::from(vec![
                Span::raw(format!("{name:<label_width$}")).bold(),
                Span::styled(
                    sparkline(&points, width, *from_zero),
                    Style::new().fg(color),
                ),
                Span::raw(format!(" {latest:>value_width$}")),
            ])
        })
        .collect();
    frame.render_widget(Paragraph::new(lines), area);
}

/// `points` (seconds before now, value; in time order) reduced to at most two per column of a
/// chart `columns` wide over the last [`HISTORY_S`]: the lowest and the highest of each column,
/// in the order they came.
fn envelope(points: impl Iterator<Item = (f64, f64)>, columns: usize) -> Vec<(f64, f64)> {
    let width = HISTORY_S / columns as f64;
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(2 * columns + 2);
    let mut column = None;
    // Indices in `out` of the current column's lowest and highest point.
    let (mut lo, mut hi) = (0, 0);
    for p in points {
        let c = ((p.0 + HISTORY_S) / width).floor() as i64;
        if column != Some(c) {
            column = Some(c);
            out.push(p);
            lo = out.len() - 1;
            hi = lo;
            continue;
        }
        if lo == hi {
            // One point so far in this column: the second becomes the other extreme.
            out.push(p);
            if p.1 < out[lo].1 {
                lo = out.len() - 1;
            } else {
                hi = out.len() - 1;
            }
        } else {
            if p.1 < out[lo].1 {
                out[lo] = p;
            } else if p.1 > out[hi].1 {
                out[hi] = p;
            }
            // Keep the column's two points in time order.
            let (first, second) = (lo.min(hi), lo.max(hi));
            if out[first].0 > out[second].0 {
                out.swap(first, second);
                std::mem::swap(&mut lo, &mut hi);
            }
        }
    }
    out
}

/// One line of a chart: its name, colour and points (seconds before now, value).
type Series<'a> = (&'a str, Color, &'a [(f64, f64)]);

/// A line's points: seconds before now, value.
type Points = Vec<(f64, f64)>;

/// One chart of the last minute: x from -60 s to now, y fitted to the data.
fn chart(frame: &mut Frame, area: Rect, title: &str, lines: &[Series<'_>], from_zero: bool) {
    let values = lines.iter().flat_map(|(_, _, d)| d.iter().map(|p| p.1));
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    let (lo, hi) = if lo.is_finite() {
        let lo = if from_zero { lo.min(0.0) } else { lo };
        let pad = ((hi - lo) * 0.1).max(if from_zero { 1.0 } else { 0.5 });
        (
            if from_zero && lo >= 0.0 {
                0.0
            } else {
                lo - pad
            },
            hi + pad,
        )
    } else {
        (0.0, 1.0)
    };
    let decimals = if hi - lo < 10.0 { 1 } else { 0 };
    let label = |v: f64| Span::raw(format!("{v:.decimals$}"));
    let datasets = lines
        .iter()
        .map(|(name, color, data)| {
            Dataset::default()
                .name(*name)
                .marker(Marker::Braille)
                .graph_type(GraphType::Line)
                .style(Style::new().fg(*color))
                .data(data)
        })
        .collect();
    // The legend goes in the title, where it hides no data.
    let mut heading = vec![Span::raw(title.to_string()).bold()];
    if lines.len() > 1 {
        for (name, color, _) in lines {
            heading.push(Span::styled(format!("  ━ {name}"), Style::new().fg(*color)));
        }
    }
    let chart = Chart::new(datasets)
        .block(Block::new().title(Line::from(heading)))
        .x_axis(
            Axis::default()
                .bounds([-HISTORY_S, 0.0])
                .labels(["-60 s", "-30 s", "now"])
                .style(Style::new().fg(Color::DarkGray)),
        )
        .y_axis(
            Axis::default()
                .bounds([lo, hi])
                .labels([label(lo), label((lo + hi) / 2.0), label(hi)])
                .style(Style::new().fg(Color::DarkGray)),
        )
        .legend_position(None);
    frame.render_widget(chart, area);
}

fn draw_log(frame: &mut Frame, area: Rect, view: View<'_>) {
    let height = area.height.saturating_sub(2) as usize;
    let items: Vec<ListItem> = view
        .log
        .iter()
        .rev()
        .take(height)
        .map(|e| {
            let style = match (e.change, e.level) {
                (Change::Cleared { .. }, _) => Style::new().fg(Color::Green),
                (_, Level::Critical) => Style::new().fg(Color::Red).add_modifier(Modifier::BOLD),
                (_, Level::Warning) => Style::new().fg(Color::Yellow),
            };
            let name = Escaped(view.escs.get(e.esc).map_or("", |esc| esc.title()));
            ListItem::new(Line::from(vec![
                Span::styled(
                    // ISO 8601: the date and time where there is room, the time of day where
                    // there is not.
                    if area.width >= WIDE / 2 + 20 {
                        format!("{} ", super::iso8601(e.t, false))
                    } else {
                        super::local_time(e.t, "%H:%M:%S ")
                    },
                    Style::new().fg(Color::DarkGray),
                ),
                Span::raw(format!(
                    "esc{} ",
                    view.escs.get(e.esc).map_or(e.esc, |esc| esc.number)
                )),
                Span::styled(e.text(), style),
                Span::styled(format!("  {name}"), Style::new().fg(Color::DarkGray)),
            ]))
        })
        .collect();
    let title = format!(" Alarms ({}) ", view.log.len());
    let list = if items.is_empty() {
        List::new([ListItem::new("no alarms".green())])
    } else {
        List::new(items)
    };
    frame.render_widget(list.block(Block::bordered().title(title)), area);
}

fn draw_help(frame: &mut Frame, session: &Session) {
    let limits = session.fleet.limits();
    let lines = vec![
        Line::from("Keys".bold()),
        Line::from("  ↑ ↓  j k  Tab   select an ESC (0-9 jump to one)"),
        Line::from("  p  space        pause / resume the display (data keeps coming)"),
        Line::from("  c               reset the peaks (↑max, ↓min) of every ESC"),
        Line::from("  r               start / stop recording everything to pcapng"),
        Line::from("  ?  h            this help (Esc closes it)"),
        Line::from("  q  Esc  Ctrl-C  quit"),
        Line::from(""),
        Line::from("Alarms".bold()),
        Line::from(format!(
            "  MOSFET ≥ {} °C warning, ≥ {} °C critical; capacitor ≥ {} / {} °C",
            limits.mos.warning, limits.mos.critical, limits.cap.warning, limits.cap.critical
        )),
        Line::from(format!(
            "  battery ≤ {} V/cell warning, ≤ {} V/cell critical",
            limits.cell.warning, limits.cell.critical
        )),
        Line::from(format!(
            "  stale after {} s without a frame; bit names: docs/PROTOCOL-NOTES.md",
            limits.stale_after_s
        )),
        Line::from("  yellow: warning, red: critical; each alarm is logged once per episode"),
        Line::from(match &session.config_file {
            Some(path) => format!("  settings from {}", path.display()),
            None => "  no configuration file (see hwfoc monitor --help)".to_string(),
        }),
    ];
    let width = 76.min(frame.area().width);
    let height = (lines.len() as u16 + 2).min(frame.area().height);
    let area = Rect {
        x: frame.area().width.saturating_sub(width) / 2,
        y: frame.area().height.saturating_sub(height) / 2,
        width,
        height,
    };
    frame.render_widget(Clear, area);
    frame.render_widget(
        Paragraph::new(lines)
            .alignment(Alignment::Left)
            .block(Block::bordered().title(" help ")),
        area,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_v4_device_line_is_its_info_fields_by_their_description() {
        // The Platinum V4 capture's info frame (the fields not given are 0).
        let (v1, v2, i2, t) = (8, 91, 1, 0x21);
        let v4 = hwfoc::v4::InfoFrame {
            full_scale: 1000,
            v1,
            v2,
            i2,
            t1: t,
            t2: t,
            ..Default::default()
        };
        assert_eq!(
            adopted_info_line(&Info::HwV4(v4), true),
            "Hobbywing V4 info: full_scale 1000 · v1 8 · v2 91 · i1 0 · i2 1 · i3 0 · t1 33 · \
             t2 33 · adopted"
        );
        assert!(
            adopted_info_line(&Info::HwV4(v4), false)
                .ends_with("· not adopted yet (two identical copies needed)")
        );
    }

    #[test]
    fn the_charts_and_their_lines() {
        type Charts = Vec<(String, Vec<(&'static str, Color)>, bool)>;
        let got: Charts = CHARTS
            .iter()
            .map(|&m| {
                let lines = m.shown().map(|q| (q.short(), colour(q))).collect();
                (chart_title(m), lines, from_zero(m))
            })
            .collect();
        let want: Charts = vec![
            ("RPM".into(), vec![("rpm", Color::Cyan)], true),
            (
                "Current A".into(),
                vec![
                    ("input", Color::Yellow),
                    ("phase", Color::Magenta),
                    ("BEC", Color::LightCyan),
                ],
                true,
            ),
            (
                "Voltage V".into(),
                vec![("input", Color::Green), ("BEC", Color::LightCyan)],
                false,
            ),
            (
                "Temperature °C".into(),
                vec![
                    ("MOS", Color::Red),
                    ("CAP", Color::LightBlue),
                    ("motor", Color::LightMagenta),
                    ("BEC", Color::LightCyan),
                ],
                false,
            ),
        ];
        assert_eq!(got, want);
        let rows: Vec<(String, usize, String)> = sparklines()
            .into_iter()
            .map(|(name, _, decimals, unit, _)| (name, decimals, unit))
            .collect();
        let want: Vec<(String, usize, String)> = vec![
            ("RPM".into(), 0, "".into()),
            ("Current".into(), 1, " A".into()),
            ("Voltage".into(), 1, " V".into()),
            ("MOS temp".into(), 0, " °C".into()),
        ];
        assert_eq!(rows, want);
    }

    #[test]
    fn the_envelope_keeps_each_columns_extremes_in_time_order() {
        // 1200 points over a minute, a spike at -30 s, into 60 columns of a second.
        let points: Vec<(f64, f64)> = (0..1200)
            .map(|i| {
                let t = -60.0 + f64::from(i) * 0.05;
                let v = if i == 600 { 100.0 } else { f64::from(i % 7) };
                (t, v)
            })
            .collect();
        let out = envelope(points.iter().copied(), 60);
        assert!(out.len() <= 120, "{}", out.len());
        assert!(out.windows(2).all(|w| w[0].0 <= w[1].0), "time order");
        assert!(out.contains(&(-30.0, 100.0)), "the spike survives");
        // Each column keeps its lowest and highest value.
        let second: Vec<f64> = out
            .iter()
            .filter(|p| (-59.0..-58.0).contains(&p.0))
            .map(|p| p.1)
            .collect();
        assert_eq!(second.len(), 2);
        assert_eq!(second.iter().cloned().fold(f64::INFINITY, f64::min), 0.0);
        assert_eq!(second.iter().cloned().fold(0.0, f64::max), 6.0);
        // Fewer points than columns pass through unchanged.
        let few = [(-10.0, 1.0), (-5.0, 2.0)];
        assert_eq!(envelope(few.iter().copied(), 60), few);
    }
}
