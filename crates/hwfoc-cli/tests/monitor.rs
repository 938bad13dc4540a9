//! `hwfoc monitor`: the dashboard driven through tmux, the headless modes, a port that goes away
//! and comes back, recording while watching, and the errors a person meets.

#![cfg(unix)]

mod common;

use std::process::Command;
use std::str::FromStr;
use std::thread;
use std::time::{Duration, Instant};

use common::{Running, TEXT_SCHEMA, hwfoc, ok, stdout};
use nix::sys::signal::Signal;
use serde_json::Value;

fn lines(out: &[u8]) -> Vec<String> {
    String::from_utf8_lossy(out)
        .lines()
        .map(str::to_string)
        .collect()
}

#[test]
fn plain_prints_each_esc_every_interval_and_alarms_by_name() {
    let out = hwfoc()
        .args([
            "monitor",
            "--sim",
            "2",
            "--plain",
            "--no-config",
            "--interval",
            "1",
            "--duration",
            "7.5",
            "--fault",
            "1:mos_overheat@3-4",
        ])
        .output()
        .expect("spawn");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let lines = lines(&out.stdout);
    for esc in 0..2 {
        let status: Vec<&String> = lines
            .iter()
            .filter(|l| l.contains(&format!(" esc{esc} sim:esc{esc}: ")))
            .filter(|l| !l.contains(" ALARM esc") && !l.contains(" CLEARED esc"))
            .collect();
        // 7 on an idle machine; a busy one may wake late and skip a line (never add one).
        assert!((4..=8).contains(&status.len()), "{lines:#?}");
        // The first line comes after a second: the idle ESC has sent frames by then.
        assert!(
            status[0].contains(" V ") && status[0].contains("fr/s"),
            "{lines:#?}"
        );
    }
    // Each ESC's power, charge and energy, and all of them together once per interval.
    let totals: Vec<&String> = lines
        .iter()
        .filter(|l| l.contains(" total: power "))
        .collect();
    assert!((4..=8).contains(&totals.len()), "{lines:#?}");
    let last_total = totals.last().unwrap();
    assert!(
        last_total.contains(" mAh ")
            && last_total.ends_with(" Wh")
            && last_total.contains("(peak "),
        "{last_total}"
    );
    let used = |l: &str| -> f64 {
        l.split("used ")
            .nth(1)
            .and_then(|s| s.split(" mAh").next())
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("no charge in {l}"))
    };
    assert!(used(last_total) > 0.0, "{last_total}");
    let last_esc = |esc: usize| {
        lines
            .iter()
            .rev()
            .find(|l| l.contains(&format!(" esc{esc} sim:esc{esc}: thr ")))
            .unwrap()
    };
    let sum = used(last_esc(0)) + used(last_esc(1));
    assert!(
        (used(last_total) - sum).abs() < 0.3,
        "{last_total} vs {sum}"
    );
    // Throttle steps start after the 2 s lead-in: the last lines show the motor turning.
    let last = lines.iter().rev().find(|l| l.contains(" esc0 ")).unwrap();
    let rpm: f64 = last
        .split(" rpm")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no rpm in {last}"));
    assert!(rpm > 1000.0, "{last}");

    // The injected overheat comes with its temperature (above 110 degC), which raises the
    // temperature alarm beside the fault's.
    let alarm = |l: &&String| l.contains(" ALARM esc") || l.contains(" CLEARED esc");
    let hot: Vec<&String> = lines
        .iter()
        .filter(alarm)
        .filter(|l| l.contains(": mos_temp "))
        .collect();
    assert!(
        hot.first()
            .is_some_and(|l| l.contains("ALARM esc1 sim:esc1: mos_temp critical raised at 11")),
        "{lines:#?}"
    );
    let alarms: Vec<&String> = lines
        .iter()
        .filter(alarm)
        .filter(|l| !l.contains(": mos_temp "))
        .collect();
    assert_eq!(alarms.len(), 2, "{lines:#?}");
    assert!(
        alarms[0].ends_with("ALARM esc1 sim:esc1: mos_overheat critical raised"),
        "{}",
        alarms[0]
    );
    // Cleared once the bit has been off for half a second: idle frames come every 364 ms, so
    // the episode lasts from 0.5 s (on for one frame) to 1.4 s (on for the whole second).
    let after: f64 = alarms[1]
        .split("cleared after ")
        .nth(1)
        .and_then(|s| s.strip_suffix(" s"))
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("{}", alarms[1]));
    assert!(
        alarms[1].contains("CLEARED esc1 sim:esc1: mos_overheat"),
        "{}",
        alarms[1]
    );
    assert!((0.5..=1.5).contains(&after), "{}", alarms[1]);
    // The status line shows the fault while it is on (at 3..4 s; a line at about 3.5 s).
    assert!(
        lines
            .iter()
            .any(|l| l.contains(" esc1 ") && l.contains("| ALARM mos_overheat(critical)")),
        "{lines:#?}"
    );
    assert!(
        lines
            .iter()
            .filter(|l| l.contains(" esc0 "))
            .all(|l| l.ends_with("| ok")),
        "{lines:#?}"
    );
}

#[test]
fn json_lines_carry_the_schema_record_link_and_alarms() {
    let out = hwfoc()
        .args([
            "monitor",
            "--sim",
            "1",
            "--json",
            "--no-config",
            "--interval",
            "0.5",
            "--duration",
            "3.2",
            "--fault",
            "throttle_signal_lost@1-1.2",
        ])
        .output()
        .expect("spawn");
    let out = ok(out);
    let values: Vec<Value> = lines(&out.stdout)
        .iter()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect();
    let status: Vec<&Value> = values.iter().filter(|v| v["type"] == "status").collect();
    assert!((5..=7).contains(&status.len()), "{values:#?}");
    let last = status.last().unwrap();
    assert_eq!(last["name"], "sim:esc0");
    assert_eq!(last["link"], "up");
    let record = last["record"].as_object().expect("a record");
    let keys: Vec<&str> = record.keys().map(String::as_str).collect();
    assert_eq!(keys, TEXT_SCHEMA);
    assert!(last["info"]["product"].is_string(), "{last}");
    assert_eq!(last["battery_cells"], 6);
    assert!(last["frame_rate_hz"].as_f64().unwrap() > 1.0);
    // Timestamps: RFC 3339 with an offset, and Unix seconds.
    let time = last["time"].as_str().unwrap();
    assert!(time.len() >= 29 && time.as_bytes()[10] == b'T', "{time}");
    assert!(last["t_s"].as_f64().unwrap() > 1.7e9);

    let alarms: Vec<&Value> = values.iter().filter(|v| v["type"] == "alarm").collect();
    assert_eq!(alarms.len(), 2, "{alarms:#?}");
    assert_eq!(alarms[0]["alarm"], "throttle_signal_lost");
    assert_eq!(alarms[0]["level"], "warning");
    assert_eq!(alarms[0]["event"], "raised");
    assert_eq!(alarms[1]["event"], "cleared");
    assert!(alarms[1]["duration_s"].as_f64().unwrap() >= 0.5);
}

#[test]
fn a_port_that_goes_away_shows_disconnected_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("esc0");
    let link = link.to_str().unwrap();
    let start_sim = || {
        let sim = Running::start(&["simulate", "--pty", "--link", link, "--quiet"]);
        sim.wait_for_stdout("esc 0:", Duration::from_secs(10));
        sim
    };
    let mut first = start_sim();
    let mut monitor = Running::start(&[
        "monitor",
        link,
        "--plain",
        "--no-config",
        "--interval",
        "0.25",
    ]);
    monitor.wait_for_stdout(" V ", Duration::from_secs(10));

    // The ESC's pty goes away: SIGTERM ends the simulator, which closes it and removes the link.
    first.signal(Signal::SIGTERM);
    assert!(first.wait(Duration::from_secs(5)));
    monitor.wait_for_stdout("disconnected critical raised", Duration::from_secs(5));
    monitor.wait_for_stdout(": disconnected for", Duration::from_secs(5));
    thread::sleep(Duration::from_millis(1000));
    assert!(
        monitor.child.try_wait().unwrap().is_none(),
        "the monitor ended when its port went away:\n{}",
        monitor.stderr()
    );

    // A new pty appears at the same path.
    let mut second = start_sim();
    // The clear names the level the alarm had.
    let cleared = monitor.wait_for_stdout(
        "disconnected critical cleared after",
        Duration::from_secs(5),
    );
    assert!(cleared.contains("CLEARED esc0"), "{cleared}");
    // Frames again, and the ESC's line is back to normal.
    monitor.wait_for_stdout("| ok", Duration::from_secs(5));
    monitor.signal(Signal::SIGTERM);
    assert!(monitor.wait(Duration::from_secs(5)), "{}", monitor.stderr());
    second.signal(Signal::SIGTERM);
    assert!(second.wait(Duration::from_secs(5)));
    // A single disconnection episode, raised once and cleared once.
    let out = monitor.stdout();
    assert_eq!(
        out.matches("disconnected critical raised").count(),
        1,
        "{out}"
    );
    assert_eq!(
        out.matches("disconnected critical cleared").count(),
        1,
        "{out}"
    );
}

#[test]
fn record_while_monitoring_writes_a_recording_that_decodes() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("watch.pcapng");
    let out = hwfoc()
        .args(["monitor", "--sim", "2", "--plain", "--no-config"])
        .args(["--duration", "2.5", "--record"])
        .arg(&path)
        .output()
        .expect("spawn");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("recorded to"), "{stderr}");
    let decoded = hwfoc().arg("decode").arg(&path).output().expect("spawn");
    assert!(decoded.status.success());
    let records: Vec<Value> = lines(&decoded.stdout)
        .iter()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    for esc in 0..2 {
        let n = records.iter().filter(|r| r["esc"] == esc).count();
        // 2.5 s idle: a frame every 364 ms.
        assert!((4..=9).contains(&n), "esc {esc}: {n} frames");
    }
}

#[test]
fn errors_say_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let check = |args: &[&str], expected: &str| {
        let out = hwfoc().arg("monitor").args(args).output().expect("spawn");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    };
    check(&["--no-config"], "hwfoc monitor --sim 4");
    check(&["--sim", "2", "--no-config"], "use --plain or --json");
    check(
        &[
            "/dev/ttyUSB0",
            "--plain",
            "--no-config",
            "--fault",
            "mos_overheat@1",
        ],
        "add --sim N",
    );
    check(
        &["/dev/ttyNOPE7", "--plain", "--no-config"],
        "no such port /dev/ttyNOPE7",
    );
    check(
        &[
            "--sim",
            "2",
            "--plain",
            "--no-config",
            "--fault",
            "5:mos_overheat@1",
        ],
        "ESC 5 does not exist",
    );
    check(
        &[
            "--sim",
            "1",
            "--plain",
            "--no-config",
            "--record",
            "/nonexistent/x.pcapng",
        ],
        "cannot write /nonexistent/x.pcapng",
    );
    check(
        &[
            "--sim",
            "1",
            "--plain",
            "--no-config",
            "--mos-warning-c",
            "110",
        ],
        "must be above the warning level",
    );
    let config = dir.path().join("monitor.toml");
    std::fs::write(&config, "baud = 19200\n\n[alarms]\nmos_warn_c = 80\n").unwrap();
    check(
        &[
            "--sim",
            "1",
            "--plain",
            "--config",
            config.to_str().unwrap(),
        ],
        "monitor.toml line 4: unknown field `mos_warn_c`",
    );
}

#[test]
fn the_configuration_file_is_found_in_the_user_configuration_directory() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("hwfoc")).unwrap();
    std::fs::write(
        dir.path().join("hwfoc/monitor.toml"),
        "[[esc]]\nport = \"sim:esc0\"\nlabel = \"tail rotor\"\n",
    )
    .unwrap();
    let out = hwfoc()
        .args(["monitor", "--sim", "1", "--plain", "--duration", "1.2"])
        .env("XDG_CONFIG_HOME", dir.path())
        .output()
        .expect("spawn");
    let text = stdout(&out);
    assert!(text.contains(" esc0 tail rotor: "), "{text}");
    // --no-config leaves it out.
    let out = hwfoc()
        .args([
            "monitor",
            "--sim",
            "1",
            "--plain",
            "--duration",
            "1.2",
            "--no-config",
        ])
        .env("XDG_CONFIG_HOME", dir.path())
        .output()
        .expect("spawn");
    let text = stdout(&out);
    assert!(text.contains(" esc0 sim:esc0: "), "{text}");
}

#[test]
fn a_configuration_file_sets_labels_and_levels() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("monitor.toml");
    // A MOSFET warning level under the simulator's ambient temperature: raised at once.
    std::fs::write(
        &config,
        "[alarms]\nmos_warning_c = 10\nmos_critical_c = 120\n\n[[esc]]\nport = \"sim:esc0\"\n\
         label = \"front left\"\n",
    )
    .unwrap();
    let out = hwfoc()
        .args(["monitor", "--sim", "1", "--plain", "--duration", "1.5"])
        .arg("--config")
        .arg(&config)
        .output()
        .expect("spawn");
    let stdout = stdout(&out);
    assert!(
        stdout.contains("ALARM esc0 front left: mos_temp warning raised at"),
        "{stdout}"
    );
    assert!(stdout.contains(" esc0 front left: thr "), "{stdout}");
}

/// A tmux server of the test's own, killed when dropped.
struct Tmux {
    socket: String,
}

/// How long the pane may take to show a key's effect: generous, as CI machines run many tests
/// at once (a wait, not a speed test: it returns as soon as the pane shows it).
const PANE_WAIT: Duration = Duration::from_secs(15);

impl Tmux {
    fn start(width: u16, height: u16) -> Tmux {
        // A server per test: tests run in parallel.
        static NEXT: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let tmux = Tmux {
            socket: format!("hwfoc-test-{}-{n}", std::process::id()),
        };
        let ok = tmux
            .cmd()
            .args(["new-session", "-d", "-s", "t", "-x", &width.to_string()])
            .args(["-y", &height.to_string(), "bash --norc --noprofile"])
            .env("TERM", "xterm-256color")
            .status()
            .unwrap_or_else(|e| panic!("tmux is needed for this test (apt install tmux): {e}"));
        assert!(ok.success());
        tmux
    }

    fn cmd(&self) -> Command {
        let mut cmd = Command::new("tmux");
        cmd.args(["-L", &self.socket]);
        cmd
    }

    fn keys(&self, keys: &[&str]) {
        let ok = self
            .cmd()
            .args(["send-keys", "-t", "t"])
            .args(keys)
            .status()
            .unwrap();
        assert!(ok.success());
    }

    fn pane(&self) -> String {
        let out = self
            .cmd()
            .args(["capture-pane", "-p", "-t", "t"])
            .output()
            .unwrap();
        String::from_utf8_lossy(&out.stdout).into_owned()
    }

    /// Waits until the pane shows what `test` looks for; returns the pane.
    fn wait(&self, what: &str, timeout: Duration, test: impl Fn(&str) -> bool) -> String {
        let until = Instant::now() + timeout;
        loop {
            let pane = self.pane();
            if test(&pane) {
                return pane;
            }
            if Instant::now() > until {
                panic!("the pane never showed {what} within {timeout:?}:\n{pane}");
            }
            thread::sleep(Duration::from_millis(100));
        }
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = self.cmd().arg("kill-server").status();
    }
}

/// Asserts that the shell's terminal is back in line mode with echo (no raw mode left behind),
/// by asking `stty`; `n` makes the answer's marker unique.
fn assert_terminal_usable(tmux: &Tmux, n: u32) {
    // The marker is computed, so that the command line itself does not match it.
    let command = format!(
        "stty -a | tr ' ;' '\\n\\n' | grep -x -e icanon -e echo | tr '\\n' ' '; \
         echo STTY-$(({n}*7))"
    );
    tmux.keys(&[&command, "Enter"]);
    let marker = format!("STTY-{}", n * 7);
    let pane = tmux.wait("stty's answer", Duration::from_secs(5), |p| {
        p.lines().any(|l| l.ends_with(&marker))
    });
    let answer = pane.lines().find(|l| l.ends_with(&marker)).unwrap();
    assert_eq!(answer.trim(), format!("icanon echo {marker}"), "{pane}");
}

/// The row of ESC `esc` in the dashboard's table.
fn row(pane: &str, esc: usize) -> Option<&str> {
    let name = format!("sim:esc{esc} ");
    pane.lines()
        .find(|l| l.contains(&name) && !l.contains('┌') && !l.contains('│'))
}

/// The numbers in a row, in order (live values and peaks).
fn numbers(row: &str) -> Vec<f64> {
    row.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter_map(|s| s.parse().ok())
        .collect()
}

#[test]
fn the_dashboard_in_tmux() {
    let dir = tempfile::tempdir().unwrap();
    let tmux = Tmux::start(160, 45);
    let command = format!(
        "{} monitor --sim 4 --no-config --fault 2:mos_overheat@3-60 --record-dir {}; \
         echo MONITOR-EXIT=$?",
        env!("CARGO_BIN_EXE_hwfoc"),
        dir.path().display()
    );
    tmux.keys(&[&command, "Enter"]);

    // One row per ESC, with plausible values: voltage of a 6S pack, temperatures near ambient.
    let pane = tmux.wait("four rows with values", Duration::from_secs(15), |p| {
        (0..4).all(|i| row(p, i).is_some_and(|r| r.contains('/')))
    });
    assert!(
        pane.contains("hwfoc monitor") && pane.contains("4 ESCs (virtual)"),
        "{pane}"
    );
    for esc in 0..4 {
        let r = row(&pane, esc).unwrap();
        let n = numbers(r);
        // esc, the N of "sim:escN", throttle in/out, rpm and its peak, volt and its minimum, current
        // and peak, phase current and peak, MOSFET temperature and peak, ...
        assert_eq!(n[0], esc as f64, "{r}");
        let volt = n[6];
        assert!(
            (20.0..=25.5).contains(&volt),
            "voltage {volt} in {r}\n{pane}"
        );
        let mos = n[12];
        assert!((15.0..=60.0).contains(&mos), "MOSFET {mos} in {r}\n{pane}");
    }
    // The first ESC is selected: its detail pane, charts and device information.
    assert!(pane.contains("┌ esc0 sim:esc0"), "{pane}");
    assert!(
        pane.contains("RPM") && pane.contains("Temperature °C"),
        "{pane}"
    );

    // Selecting the next ESC changes the detail pane.
    tmux.keys(&["Down"]);
    tmux.wait("esc1's detail pane", PANE_WAIT, |p| {
        p.contains("┌ esc1 sim:esc1")
    });
    tmux.keys(&["3"]);
    tmux.wait("esc3's detail pane", PANE_WAIT, |p| {
        p.contains("┌ esc3 sim:esc3")
    });

    // The injected fault reaches the log by name, and the ESC's row.
    let pane = tmux.wait("the fault in the log", Duration::from_secs(10), |p| {
        p.contains("esc2 mos_overheat critical raised")
    });
    assert!(row(&pane, 2).unwrap().contains("mos_overheat"), "{pane}");
    assert!(!row(&pane, 1).unwrap().contains("mos_overheat"), "{pane}");

    // Pause freezes the display; the peaks can be reset.
    tmux.keys(&["p"]);
    tmux.wait("PAUSED", PANE_WAIT, |p| p.contains("PAUSED"));
    tmux.keys(&["p"]);
    tmux.wait("live again", PANE_WAIT, |p| !p.contains("PAUSED"));
    tmux.keys(&["c"]);
    tmux.wait("the peaks reset", PANE_WAIT, |p| p.contains("peaks reset"));

    // r starts a recording in --record-dir and stops it; it decodes.
    tmux.keys(&["r"]);
    tmux.wait("recording", PANE_WAIT, |p| p.contains("● REC"));
    thread::sleep(Duration::from_millis(1500));
    tmux.keys(&["r"]);
    tmux.wait("recorded", PANE_WAIT, |p| {
        p.contains("recorded to") && !p.contains("● REC")
    });
    let files: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let name = files[0].file_name().unwrap().to_string_lossy().into_owned();
    assert!(
        name.starts_with("hwfoc-") && name.ends_with(".pcapng"),
        "{name}"
    );
    let decoded = hwfoc()
        .arg("decode")
        .arg(&files[0])
        .output()
        .expect("spawn");
    assert!(decoded.status.success());
    assert!(
        lines(&decoded.stdout).len() >= 4 * 10,
        "{}",
        lines(&decoded.stdout).len()
    );

    // A smaller terminal: the dashboard redraws to fit.
    let ok = tmux
        .cmd()
        .args(["resize-window", "-t", "t", "-x", "110", "-y", "30"])
        .status()
        .unwrap();
    assert!(ok.success());
    tmux.wait("the table at 110 columns", PANE_WAIT, |p| {
        p.lines().all(|l| l.chars().count() <= 110)
            && (0..4).all(|i| row(p, i).is_some())
            && p.lines().count() <= 30
            && p.contains("┌ esc3")
    });

    // Help opens and closes.
    tmux.keys(&["?"]);
    tmux.wait("the help", PANE_WAIT, |p| p.contains("reset the peaks"));
    tmux.keys(&["Escape"]);
    tmux.wait("the help closed", PANE_WAIT, |p| {
        !p.contains("reset the peaks") && p.contains("sim:esc0")
    });

    // q quits with success and gives the terminal back as it was.
    tmux.keys(&["q"]);
    let pane = tmux.wait("the exit", Duration::from_secs(5), |p| {
        p.contains("MONITOR-EXIT=0")
    });
    assert!(
        !pane.contains("Alarms ("),
        "the dashboard is still on screen:\n{pane}"
    );
    assert_terminal_usable(&tmux, 6);

    // Ctrl-C quits as cleanly.
    tmux.keys(&["clear", "Enter"]);
    let command = format!(
        "{} monitor --sim 1 --no-config; echo CTRL-C-EXIT=$?",
        env!("CARGO_BIN_EXE_hwfoc")
    );
    tmux.keys(&[&command, "Enter"]);
    tmux.wait("the dashboard again", Duration::from_secs(10), |p| {
        row(p, 0).is_some()
    });
    tmux.keys(&["C-c"]);
    tmux.wait("the exit", Duration::from_secs(5), |p| {
        p.contains("CTRL-C-EXIT=0")
    });
    assert_terminal_usable(&tmux, 7);
}

/// Whether `c` is a braille dot pattern (what the charts draw with).
fn braille(c: char) -> bool {
    ('\u{2801}'..='\u{28FF}').contains(&c)
}

#[test]
fn the_dashboard_at_80_by_24_is_readable() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    let tmux = Tmux::start(80, 24);
    // The recording directory left to its default: under XDG_DATA_HOME, made on demand.
    let command = format!(
        "XDG_DATA_HOME={} {} monitor --sim 4 --no-config; echo MONITOR-EXIT=$?",
        data.display(),
        env!("CARGO_BIN_EXE_hwfoc")
    );
    tmux.keys(&[&command, "Enter"]);
    let pane = tmux.wait("four rows and sparklines", Duration::from_secs(15), |p| {
        (0..4).all(|i| row(p, i).is_some_and(|r| r.contains('/')))
            && p.lines()
                .filter(|l| l.contains("▁") || l.contains("█"))
                .count()
                >= 3
    });
    // No chart squeezed into a row or two: sparklines instead, one per quantity, labelled.
    assert!(!pane.chars().any(braille), "{pane}");
    for name in ["RPM", "Current", "Voltage", "MOS temp"] {
        let line = pane
            .lines()
            .find(|l| l.contains(&format!("│{name} ")))
            .unwrap_or_else(|| panic!("no {name} sparkline:\n{pane}"));
        assert!(line.chars().count() <= 80, "{line}");
    }
    assert!(pane.lines().count() <= 24 && pane.lines().all(|l| l.chars().count() <= 80));
    // Energy of the selected ESC and of all of them, and the time as ISO 8601.
    assert!(
        pane.contains("this ESC") && pane.contains("all ESCs"),
        "{pane}"
    );
    assert!(pane.contains(" mAh") && pane.contains(" Wh"), "{pane}");
    let title = pane.lines().next().unwrap();
    let iso = title
        .split_whitespace()
        .find(|w| w.len() >= 25 && w.as_bytes()[10] == b'T')
        .unwrap_or_else(|| panic!("no ISO 8601 time in {title}"));
    assert!(jiff::Timestamp::from_str(iso).is_ok(), "{iso}");

    // r records into the data directory, made private, and says where.
    tmux.keys(&["r"]);
    tmux.wait("recording", PANE_WAIT, |p| p.contains("● REC"));
    thread::sleep(Duration::from_millis(800));
    tmux.keys(&["r"]);
    tmux.wait("recorded", PANE_WAIT, |p| p.contains("recorded to"));
    let recordings = data.join("hwfoc/recordings");
    let files: Vec<_> = std::fs::read_dir(&recordings).unwrap().collect();
    assert_eq!(files.len(), 1);
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&recordings).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o700, "{mode:o}");
    }

    // Wide enough for charts: their axis labels never run together.
    let ok = tmux
        .cmd()
        .args(["resize-window", "-t", "t", "-x", "160", "-y", "50"])
        .status()
        .unwrap();
    assert!(ok.success());
    let pane = tmux.wait("the charts", Duration::from_secs(5), |p| {
        p.chars().filter(|&c| braille(c)).count() > 10 && p.contains("-30 s")
    });
    assert!(!pane.contains("now-60"), "{pane}");
    let labels = pane
        .lines()
        .find(|l| l.contains("now") && l.contains("-60 s") && l.contains("-30 s"))
        .unwrap_or_else(|| panic!("no axis labels:\n{pane}"));
    let gap = labels.split("now").nth(1).unwrap();
    assert!(gap.starts_with("   "), "labels too close: {labels}");

    tmux.keys(&["q"]);
    let pane = tmux.wait("the exit", Duration::from_secs(5), |p| {
        p.contains("MONITOR-EXIT=0")
    });
    // Where the recording went is said on exit too.
    assert!(pane.contains("hwfoc: recorded to"), "{pane}");
    assert!(pane.contains("hwfoc/recordings/hwfoc-"), "{pane}");
}

/// An idle ESC's current sensor reads -1 LSB (the simulator's ESC 1 does, as a real XRotor
/// does): its power is a few tenths of a watt below zero. The text shows `0 W`, `0.0 mAh` and
/// `0.00 Wh`, never `-0`, and a peak of power drawn is never below zero.
#[test]
fn an_idle_esc_shows_no_negative_zero_and_no_negative_peak() {
    let run = |mode: &str| {
        ok(hwfoc()
            .args([
                "monitor",
                "--sim",
                "2",
                mode,
                "--no-config",
                "--interval",
                "0.5",
                "--duration",
                "2.2",
            ])
            .output()
            .expect("spawn"))
    };
    let plain = String::from_utf8(run("--plain").stdout).unwrap();
    assert!(plain.contains(" esc1 "), "{plain}");
    for word in plain.split_whitespace() {
        let digits = word.trim_start_matches('-');
        assert!(
            !(word.starts_with('-')
                && !digits.is_empty()
                && digits.bytes().all(|b| b == b'0' || b == b'.')),
            "negative zero {word:?} in {plain}"
        );
    }
    let json = String::from_utf8(run("--json").stdout).unwrap();
    let mut negative_current = false;
    for line in json.lines() {
        let v: Value = serde_json::from_str(line).unwrap();
        if let Some(i) = v["record"]["current_a"].as_f64() {
            negative_current |= i < 0.0;
        }
        if let Some(peak) = v["energy"]["peak_power_w"].as_f64() {
            assert!(peak >= 0.0, "{line}");
        }
    }
    // The case the test is about: an ESC that reported a negative current.
    assert!(negative_current, "{json}");
}

/// The speed a pseudo-terminal is set to (`c_ospeed` of its `termios2`).
#[cfg(target_os = "linux")]
fn pty_speed(fd: &std::os::fd::OwnedFd) -> u32 {
    use nix::libc;
    use std::os::fd::AsRawFd;
    let mut t: libc::termios2 = unsafe { std::mem::zeroed() };
    // SAFETY: TCGETS2 fills a termios2 of a terminal's fd; the fd is open.
    let r = unsafe { libc::ioctl(fd.as_raw_fd(), libc::TCGETS2, &mut t) };
    assert_eq!(r, 0, "TCGETS2");
    t.c_ospeed
}

/// An HW5 ESC on a pseudo-terminal that speaks only while the terminal is set to 115200 baud
/// (garbage otherwise, as a UART at another rate reads): the monitor, given no rate, finds it,
/// says so, and shows the format's figures only (BEC voltage; no packet loss: null).
#[cfg(target_os = "linux")]
#[test]
fn an_hw5_esc_is_found_at_115200_and_shown_with_its_own_fields() {
    use std::io::Write;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    let pair = hwfoc_sim::pty::RawPair::open().unwrap();
    let path = pair.path.to_str().unwrap().to_string();
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let esc = thread::spawn(move || {
        let mut master = pair.master;
        let mut seed = 5u32;
        let mut i = 0u16;
        while !flag.load(Ordering::Relaxed) {
            let bytes: Vec<u8> = if pty_speed(&pair.slave) == 115_200 {
                hwfoc::hw5::TelemetryFrame {
                    throttle: 30,
                    erpm_raw: 1000 + i,
                    voltage_raw: 252,
                    current_raw: 55,
                    esc_temp: 41,
                    bec_temp: 35,
                    motor_temp: 38,
                    bec_voltage_raw: 84,
                    bec_current_raw: 12,
                    ..Default::default()
                }
                .encode()
                .to_vec()
            } else {
                (0..40)
                    .map(|_| {
                        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                        (seed >> 24) as u8
                    })
                    .collect()
            };
            i = i.wrapping_add(1);
            let _ = master.write_all(&bytes);
            thread::sleep(Duration::from_millis(20));
        }
    });
    let started = std::time::Instant::now();
    let mut monitor = Running::start(&[
        "monitor",
        &path,
        "--json",
        "--no-config",
        "--interval",
        "0.25",
    ]);
    let status = monitor.wait_for_stdout("\"bec_voltage_v\":8.4", Duration::from_secs(10));
    let took = started.elapsed();
    eprintln!("HW5 found and shown after {took:?}");
    assert!(took < Duration::from_secs(4), "{took:?}");
    let v: serde_json::Value = serde_json::from_str(&status).unwrap();
    assert_eq!(v["protocol"], "hw5", "{status}");
    assert_eq!(v["baud"], 115_200);
    assert_eq!(v["lost_packets"], serde_json::Value::Null);
    assert_eq!(v["restarts"], serde_json::Value::Null);
    assert_eq!(v["checksum_failures"], 0);
    assert_eq!(v["rejected_candidates"], serde_json::Value::Null);
    assert!(v.get("delivery_ratio").is_some(), "{status}");
    assert!(v["bytes_at_other_rates"].as_u64().unwrap() > 0, "{status}");
    assert_eq!(v["record"]["phase_current_a"], serde_json::Value::Null);
    monitor.signal(Signal::SIGTERM);
    assert!(monitor.wait(Duration::from_secs(5)));
    let stderr = monitor.stderr();
    assert!(
        stderr.contains(&format!("hwfoc: {path}: 115200 baud (HW5)")),
        "{stderr}"
    );
    stop.store(true, Ordering::Relaxed);
    esc.join().unwrap();
}

/// A simulated CAN bus of three Hobbywing ESCs (nodes 10, 11, 12 on throttle channels 1, 2, 3)
/// watched by `monitor slcan:PTY --json`: every status line, from the first, numbers node n as
/// ESC n - 10, as `decode` of the bus recorded does (a node heard before its GetEscID answer is
/// held until it answers), and `[esc.1]`'s label is on ESC 1 only.
#[test]
fn live_can_escs_are_numbered_as_decode_numbers_them_and_labelled_by_number() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("monitor.toml");
    std::fs::write(&config, "[esc.1]\nlabel = \"left\"\n").unwrap();
    let sim = Running::start(&["simulate", "--protocol", "hw-can", "--escs", "3", "--pty"]);
    let line = sim.wait_for_stdout("slcan: ", Duration::from_secs(20));
    let bus = format!("slcan:{}", line.trim_start_matches("slcan: ").trim());
    let out = hwfoc()
        .args([
            "monitor",
            &bus,
            "--json",
            "--interval",
            "0.5",
            "--duration",
            "4",
        ])
        .arg("--config")
        .arg(&config)
        .output()
        .expect("spawn");
    let out = ok(out);
    let mut nodes = std::collections::BTreeSet::new();
    for l in lines(&out.stdout) {
        let v: Value = serde_json::from_str(&l).unwrap_or_else(|e| panic!("{e}: {l}"));
        if v["type"] == "status" && v["record"].is_object() {
            let node = v["record"]["node"].as_u64().unwrap();
            assert_eq!(v["esc"].as_u64(), Some(node - 10), "{l}");
            let expected = if node == 11 {
                "left".into()
            } else {
                Value::Null
            };
            assert_eq!(v["label"], expected, "{l}");
            nodes.insert(node);
        }
    }
    assert_eq!(nodes.into_iter().collect::<Vec<_>>(), [10, 11, 12]);
}
