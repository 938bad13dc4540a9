"""hwfoc.open_ports: live records from serial ports (pseudo-terminals here), a lost port as a
warning, Ctrl-C as KeyboardInterrupt, errors with the command's messages."""

import os
import signal
import subprocess
import sys
import threading
import time
import warnings

import pytest

import hwfoc
from conftest import cli_error, run_cli


def _pty():
    master, slave = os.openpty()
    return master, slave, os.ttyname(slave)


def _close_after(ports, seconds):
    """Closes the ports after `seconds` (the iterator then ends), so that a test waiting for
    records that never come fails instead of hanging."""
    timer = threading.Timer(seconds, ports.close)
    timer.daemon = True
    timer.start()
    return timer


def test_records_arrive_from_ports(sim_dir):
    data = (sim_dir / "one.bin").read_bytes()[: 24 * 120]
    expected = hwfoc.read(data).to_pylist()
    expected1 = hwfoc.read(data[: 24 * 20]).to_pylist()
    assert len(expected) > 60 and len(expected1) >= 5
    m0, s0, name0 = _pty()
    m1, s1, name1 = _pty()
    try:
        with hwfoc.open_ports([name0, name1]) as ports:
            timer = _close_after(ports, 30)
            assert ports.ports == [name0, name1]
            os.write(m0, data)
            os.write(m1, data[: 24 * 20])
            got = []
            t0 = time.time()
            for record in ports:
                got.append(record)
                if len(got) == len(expected) + len(expected1):
                    break
            timer.cancel()
            stats = ports.stats
        by_esc = {e: [r for r in got if r["esc"] == e] for e in (0, 1)}
        assert [r["packet"] for r in by_esc[0]] == [r["packet"] for r in expected]
        assert [r["packet"] for r in by_esc[1]] == [r["packet"] for r in expected1]
        assert all(abs(r["t_s"] - t0) < 30 for r in got)
        for g, e in zip(by_esc[0], expected):
            # The receive times (`t_s` and its `time`) are the ports'.
            assert {k: v for k, v in g.items() if k not in ("t_s", "time")} == {
                k: v for k, v in e.items() if k not in ("t_s", "time")}
        assert stats[0]["frames"] == len(expected) and stats[1]["bytes"] == 24 * 20
        # Closed: the iterator ends.
        assert list(ports) == []
    finally:
        for fd in (m0, s0, m1, s1):
            os.close(fd)


def test_a_lost_port_is_a_warning():
    m, s, name = _pty()
    ports = hwfoc.open_ports([name])
    os.close(m)  # a hang-up: reads of the port fail, as when a USB adapter is unplugged
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")

        def close_once_warned():
            deadline = time.time() + 10
            while time.time() < deadline and not caught:
                time.sleep(0.05)
            ports.close()

        closer = threading.Thread(target=close_once_warned)
        closer.start()
        assert list(ports) == []
        closer.join()
    os.close(s)
    lost = [w for w in caught if issubclass(w.category, hwfoc.PortWarning)]
    assert lost and str(lost[0].message).startswith(f"{name} lost ("), [str(w.message) for w in caught]


def test_ctrl_c_raises_keyboard_interrupt(tmp_path):
    m, s, name = _pty()
    script = f"""
import sys, hwfoc
ports = hwfoc.open_ports([{name!r}])
print("ready", flush=True)
try:
    for record in ports:
        pass
except KeyboardInterrupt:
    print("interrupted", flush=True)
    sys.exit(3)
"""
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "ready"
        time.sleep(0.3)
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=10)
        assert p.returncode == 3, err
        assert out.strip() == "interrupted"
    finally:
        p.kill()
        os.close(m)
        os.close(s)


def test_port_errors_are_the_commands(cli, tmp_path):
    missing = "/dev/ttyUSB_hwfoc_missing"
    with pytest.raises(hwfoc.PortError) as e:
        hwfoc.open_ports([missing])
    assert str(e.value) == cli_error(cli, "decode", missing)
    m, s, name = _pty()
    try:
        with pytest.raises(hwfoc.PortError) as e:
            hwfoc.open_ports([name, name])
        assert str(e.value) == cli_error(cli, "decode", name, name)
    finally:
        os.close(m)
        os.close(s)
    with pytest.raises(ValueError):
        hwfoc.open_ports([])


def test_reading_a_port_as_a_file_is_refused():
    # `read` and `scan` would wait for the port's bytes forever, without receive times.
    master, slave, name = _pty()
    try:
        for call in (hwfoc.read, hwfoc.scan, hwfoc.summary):
            with pytest.raises(hwfoc.InputError, match="is a serial port: read it live with hwfoc.open_ports"):
                call(name)
    finally:
        os.close(master)
        os.close(slave)


def _slcan_lines(candump: str) -> bytes:
    """The frames of a candump log (`(t) can0 ID#DATA` lines, extended ids) as the lines an
    SLCAN adapter sends: `T` + eight hex digits of the id + the length + the data."""
    out = []
    for line in candump.splitlines():
        frame = line.split()[2]
        ident, data = frame.split("#")
        assert len(ident) == 8, line
        out.append(f"T{ident}{len(data) // 2}{data}\r")
    return "".join(out).encode()


def test_closing_hands_on_the_can_records_held(cli, tmp_path):
    # ESCs that never answer GetEscID: their records are held until the stream places the
    # nodes by their ids (a second after they are heard), or until it ends. Closed before
    # that, the ports still give every record, as a recording of the same frames does.
    log = tmp_path / "bus.log"
    run_cli(cli, "simulate", "--protocol", "hw-can", "--escs", "2", "--duration", "0.3",
            "--no-ask-ids", "-o", str(log))
    expected = hwfoc.read(str(log)).to_pylist()
    assert len(expected) > 20
    m, s, name = _pty()
    try:
        ports = hwfoc.open_ports([f"slcan:{name}"])
        os.write(m, _slcan_lines(log.read_text()))
        # Read until closed, 0.5 s after the frames were written: the iterator gives what the
        # stream held, then ends.
        _close_after(ports, 0.5)
        got = list(ports)
        assert len(got) == len(expected)
        assert sorted((r["esc"], r["packet"]) for r in got) == sorted(
            (r["esc"], r["packet"]) for r in expected)
        # Closed: the iterator ends.
        assert list(ports) == []
    finally:
        os.close(m)
        os.close(s)
