"""The package probed the way a hostile caller would (issues 29 and 30): Ctrl-C inside a file
object's read(), numbers out of range, times out of range, a stream that changes format, and a
CAN log fed to the byte decoder. Each is refused with a clear error, never a bare
OverflowError, a wrong figure or silence."""

import datetime

import pytest

import hwfoc
from conftest import cli_error, run_cli


class Interrupting:
    """A binary file object whose read() is interrupted by Ctrl-C (or raises what it is given)."""

    name = "interrupting.bin"

    def __init__(self, error):
        self.error = error

    def read(self, n=-1):
        raise self.error


@pytest.mark.parametrize("error", [KeyboardInterrupt, SystemExit(3)], ids=["ctrl-c", "exit"])
def test_a_base_exception_inside_read_propagates_as_itself(error):
    expected = error if isinstance(error, type) else type(error)
    with pytest.raises(expected):
        hwfoc.read(Interrupting(error))
    with pytest.raises(expected):
        next(iter(hwfoc.scan(Interrupting(error))))


def test_an_exception_inside_read_is_still_an_input_error():
    with pytest.raises(hwfoc.InputError, match="disk on fire"):
        hwfoc.read(Interrupting(OSError("disk on fire")))


@pytest.mark.parametrize(
    "call, argument",
    [
        (lambda v: hwfoc.Decoder(esc=v), "esc"),
        (lambda v: hwfoc.CanDecoder(esc=v), "esc"),
        (lambda v: hwfoc.Decoder(baud=v), "baud"),
        (lambda v: hwfoc.open_ports([], baud=v), "baud"),
        (lambda v: hwfoc.scan(b"", batch_rows=v), "batch_rows"),
    ],
    ids=["Decoder-esc", "CanDecoder-esc", "Decoder-baud", "open_ports-baud", "scan-batch_rows"],
)
@pytest.mark.parametrize("value", [-1, 2**70])
def test_integers_out_of_range_name_the_argument_and_its_range(call, argument, value):
    with pytest.raises(ValueError, match=rf"^{argument}: {value} is out of range: give \d+ to \d+\b"):
        call(value)


@pytest.mark.parametrize(
    "call",
    [
        lambda v: hwfoc.Decoder(pole_pairs=v),
        lambda v: hwfoc.CanDecoder(pole_pairs=v),
        lambda v: hwfoc.read(b"", pole_pairs=v),
        lambda v: hwfoc.scan(b"", pole_pairs=v),
        lambda v: hwfoc.summary(b"", pole_pairs=v),
        lambda v: hwfoc.open_ports([], pole_pairs=v),
    ],
    ids=["Decoder", "CanDecoder", "read", "scan", "summary", "open_ports"],
)
@pytest.mark.parametrize("value", [-1, 2**70])
def test_pole_pairs_out_of_range_are_a_settings_error(call, value):
    with pytest.raises(hwfoc.SettingsError, match=rf"pole_pairs: {value} is out of range: give 1 to 65535"):
        call(value)


def test_a_datetime_without_unix_time_is_refused_in_hwfocs_words():
    with pytest.raises(ValueError, match=r"^start: 0001-01-01 00:00:00 has no Unix time"):
        hwfoc.read(b"\x9b", start=datetime.datetime.min)


@pytest.mark.parametrize("t", [2e10, -1.0, float("nan")])
def test_feed_refuses_a_time_out_of_range(t):
    with pytest.raises(ValueError, match=r"^t: .* is not a time in seconds since 1970: give 0 to 18446744073"):
        hwfoc.Decoder().feed(b"\x9b", t=t)


def test_decoder_stats_count_every_formats_frames(cli, tmp_path):
    """A stream that changes from HW-FOC to HW5: the frames counted are the rows given."""
    parts = []
    for protocol in ("hw-foc", "hw5"):
        path = tmp_path / f"{protocol}.bin"
        run_cli(cli, "simulate", "-q", "-o", path, "--protocol", protocol, "--duration", "4", "--seed", "5")
        parts.append(path.read_bytes())
    decoder = hwfoc.Decoder()
    # A silence between the two, as when the ESC is swapped: the stream takes the new format.
    rows = sum(decoder.feed(part, t=1000.0 + 100 * i).num_rows for i, part in enumerate(parts))
    rows += decoder.finish().num_rows
    assert rows >= 20
    assert decoder.stats["frames"] == rows


def test_a_candump_log_fed_to_the_byte_decoder_is_refused():
    log = b"(1700000000.000000) can0 1401550B#0011223344556677\n"
    with pytest.raises(hwfoc.InputError, match=r"candump log.*hwfoc\.CanDecoder"):
        hwfoc.Decoder().feed(log)


@pytest.mark.parametrize(
    "call",
    ["hwfoc.read('/dev/urandom')", "next(iter(hwfoc.scan('/dev/urandom')))",
     "hwfoc.summary('/dev/urandom')"],
)
def test_ctrl_c_stops_reading_an_endless_input(call):
    """An endless input (/dev/urandom: bytes that never make a frame) is read until Ctrl-C,
    which then stops it at once as KeyboardInterrupt (every reading loop looks for signals)."""
    import signal
    import subprocess
    import sys
    import time

    code = f"import hwfoc, sys\nprint('reading', flush=True)\ntry:\n    {call}\nexcept KeyboardInterrupt:\n    sys.exit(42)\n"
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        assert p.stdout.readline() == b"reading\n"
        time.sleep(1.0)
        p.send_signal(signal.SIGINT)
        p.wait(timeout=10)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    assert p.returncode == 42, p.stderr.read().decode()


def test_dev_zero_ends_as_the_command_does(cli):
    """/dev/zero never ends, but nothing but zeros is no telemetry: reading stops after 64 MiB
    with the command's error, in every reading call."""
    expected = cli_error(cli, "decode", "/dev/zero")
    assert expected == "/dev/zero: only zero bytes, not telemetry (the first 64 MiB; reading stopped)"
    for call in (hwfoc.read, lambda p: list(hwfoc.scan(p)), hwfoc.summary):
        with pytest.raises(hwfoc.InputError) as e:
            call("/dev/zero")
        assert str(e.value) == expected
