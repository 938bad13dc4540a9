"""hwfoc.read: the same records as `hwfoc decode`, the schema and metadata of its Parquet
output, every kind of source, selections and settings, and errors with the command's
messages."""

import io
import datetime
import inspect
import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import hwfoc
from conftest import CAPTURES, assert_same_records, cli_error, cli_records, run_cli, simulate


@pytest.mark.parametrize("capture", CAPTURES, ids=lambda p: p.name)
def test_real_captures_equal_decode(cli, capture):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hwfoc.HwfocWarning)
        table = hwfoc.read(str(capture))
    records = cli_records(cli, capture)
    assert_same_records(table, records)


def test_the_real_captures_hold_frames():
    # The comparison above is not empty: the Platinum Pro V3 and Platinum V4 captures and the
    # X-Rotor capture's HW-FOC frames, each with its protocol (test_protocols.py reads them).
    sizes, protocols = [], []
    for c in CAPTURES:
        table = hwfoc.read(str(c))
        sizes.append(table.num_rows)
        protocols.append(set(table.column("protocol").to_pylist()))
    assert sizes == [699, 297, 248], sizes
    assert protocols == [{"hw-v3"}, {"hw-v4"}, {"hw-foc"}], protocols


@pytest.mark.parametrize("name", ["three.pcapng", "one.bin"])
def test_simulated_recordings_equal_decode(cli, sim_dir, name):
    path = sim_dir / name
    table = hwfoc.read(path)
    records = cli_records(cli, path)
    assert len(records) > 100
    assert any(r["faults"] for r in records)
    assert_same_records(table, records)


def test_time_is_a_utc_timestamp_to_pandas_polars_and_duckdb(sim_dir):
    """Record schema 4: `time` holds `t_s`'s instant as a UTC timestamp, which pandas, polars
    and DuckDB take as a time with no conversion."""
    table = hwfoc.read(sim_dir / "three.pcapng")
    assert table.schema.field("time").type == pa.timestamp("us", tz="UTC")
    t_s = table.column("t_s").to_pylist()
    first = datetime.datetime.fromtimestamp(t_s[0], datetime.timezone.utc)
    assert abs(table.column("time")[0].as_py() - first) < datetime.timedelta(microseconds=1)
    frame = table.select(["t_s", "time"]).to_pandas()
    assert str(frame["time"].dtype) == "datetime64[us, UTC]"
    assert ((frame["time"].astype("int64") - frame["t_s"] * 1e6).abs() <= 0.5).all()
    polars = pytest.importorskip("polars")
    df = polars.from_arrow(table.select(["t_s", "time"]))
    us = (df["t_s"] * 1e6).round(mode="half_away_from_zero").cast(polars.Int64)
    assert (df["time"].dt.epoch("us") == us).all()
    assert df.schema["time"] == polars.Datetime("us", "UTC")
    duckdb = pytest.importorskip("duckdb")
    records = table  # noqa: F841 (DuckDB reads the local variable by its name)
    kind, differ = duckdb.sql(
        "SELECT any_value(typeof(time)), count(*) FILTER (WHERE epoch_us(time) != round(t_s * 1e6)) "
        "FROM records").fetchall()[0]
    assert (kind, differ) == ("TIMESTAMP WITH TIME ZONE", 0)


def test_schema_and_metadata_are_the_parquet_exports(cli, sim_dir, tmp_path):
    path = str(sim_dir / "three.pcapng")
    out = tmp_path / "x.parquet"
    run_cli(cli, "decode", "--format", "parquet", "-o", out, path, "--esc", "0,2", "--from", "1700000002")
    table = hwfoc.read(path, esc=[0, 2], start=1700000002)
    exported = pq.read_table(out)
    assert table.schema.equals(exported.schema, check_metadata=False)
    # Field by field, with the units.
    for got, want in zip(table.schema, exported.schema):
        assert got.name == want.name and got.type == want.type and got.nullable == want.nullable
        assert got.metadata == want.metadata
    file_meta = pq.read_metadata(out).metadata
    for key, value in table.schema.metadata.items():
        assert file_meta[key] == value, key
    assert set(table.schema.metadata) == {k for k in file_meta if k != b"ARROW:schema"}
    assert table.schema.metadata[b"filter"] == b"esc=0,2 from=1700000002"
    # `protocol` is a dictionary on both sides, but a Parquet reader makes its own dictionary
    # (of the names in the file) where hwfoc's holds every protocol's: the same values, compared
    # as strings.
    def decoded(t):
        at = t.schema.get_field_index("protocol")
        return t.set_column(at, "protocol", t.column("protocol").cast(pa.string()))

    assert pa.types.is_dictionary(table.schema.field("protocol").type)
    assert decoded(table).equals(decoded(exported))


def test_settings_change_values_and_metadata(cli, sim_dir):
    path = sim_dir / "one.bin"
    table = hwfoc.read(path, current_scale=100, pole_pairs=14, gear_ratio=2.5)
    records = cli_records(cli, path, "--current-scale", "100", "--pole-pairs", "14", "--gear-ratio", "2.5")
    assert_same_records(table, records)
    meta = table.schema.metadata
    assert (meta[b"current_scale"], meta[b"pole_pairs"], meta[b"gear_ratio"]) == (b"100", b"14", b"2.5")
    assert table.column("rpm") != hwfoc.read(path).column("rpm")


def test_the_default_settings_are_the_librarys(sim_dir):
    # docs/RECORD-SCHEMA.md: current scale 64, 7 pole pairs, gear ratio 1, 8/910 V per V4 step.
    defaults = (hwfoc.DEFAULT_CURRENT_SCALE, hwfoc.DEFAULT_POLE_PAIRS, hwfoc.DEFAULT_GEAR_RATIO,
                hwfoc.DEFAULT_V4_VOLTS_PER_STEP)
    assert defaults == (64.0, 7, 1.0, "8/910")
    assert isinstance(hwfoc.DEFAULT_POLE_PAIRS, int)
    meta = hwfoc.record_schema().metadata
    names = ("current_scale", "pole_pairs", "gear_ratio", "v4_volts_per_step")
    assert tuple(meta[name.encode()] for name in names) == (b"64", b"7", b"1", b"8/910")
    for f in (hwfoc.read, hwfoc.scan, hwfoc.summary, hwfoc.record_schema, hwfoc.Decoder, hwfoc.open_ports):
        params = inspect.signature(f).parameters
        got = tuple(params[name].default for name in names)
        assert got == defaults, f
    path = sim_dir / "one.bin"
    given = hwfoc.read(path, **dict(zip(names, defaults)))
    assert given.equals(hwfoc.read(path))


@pytest.mark.parametrize("esc,start,end", [(1, None, None), ([0, 2], 1700000003.5, None), (None, None, 1700000004), (2, 1700000002, 1700000006)])
def test_selection_is_the_commands(cli, sim_dir, esc, start, end):
    path = sim_dir / "three.pcapng"
    args = []
    if esc is not None:
        args += ["--esc", ",".join(map(str, esc if isinstance(esc, list) else [esc]))]
    if start is not None:
        args += ["--from", start]
    if end is not None:
        args += ["--to", end]
    table = hwfoc.read(path, esc=esc, start=start, end=end)
    records = cli_records(cli, path, *args)
    assert 0 < len(records) < hwfoc.read(path).num_rows
    assert_same_records(table, records)


def test_a_datetime_selects_as_its_unix_time(sim_dir):
    import datetime

    path = sim_dir / "three.pcapng"
    when = datetime.datetime.fromtimestamp(1700000004, tz=datetime.timezone.utc)
    assert hwfoc.read(path, start=when).equals(hwfoc.read(path, start=1700000004))


def test_bytes_and_file_objects_read_as_the_file(sim_dir):
    path = sim_dir / "three.pcapng"
    whole = hwfoc.read(path)
    data = path.read_bytes()
    for source in (data, bytearray(data), memoryview(data), io.BytesIO(data)):
        got = hwfoc.read(source)
        assert got.equals(whole)
    with open(path, "rb") as f:
        got = hwfoc.read(f)
    assert got.equals(whole)
    assert json.loads(got.schema.metadata[b"inputs"]) == [str(path)]
    assert json.loads(hwfoc.read(data).schema.metadata[b"inputs"]) == ["<bytes>"]


def test_inputs_given_together(cli, sim_dir):
    a, b = sim_dir / "one.bin", sim_dir / "three.pcapng"
    table = hwfoc.read([a, str(b)])
    assert_same_records(table, cli_records(cli, a, b))
    escs = json.loads(table.schema.metadata[b"escs"])
    assert [e["esc"] for e in escs] == [0, 1, 2, 3]
    assert set(table.column("esc").to_pylist()) == {0, 1, 2, 3}


def test_empty_window_and_bad_settings_raise_the_commands_errors(cli, sim_dir):
    path = sim_dir / "three.pcapng"
    with pytest.raises(hwfoc.SelectionError) as e:
        hwfoc.read(path, start=5, end=5)
    # The command's message, naming the keyword arguments where it names its options.
    assert str(e.value) == "start 5 is not before end 5: no frame can be selected"
    assert cli_error(cli, "decode", path, "--from", "5", "--to", "5") == (
        "--from 5 is not before --to 5: no frame can be selected"
    )
    with pytest.raises(hwfoc.SettingsError) as e:
        hwfoc.read(path, current_scale=0)
    assert str(e.value) == cli_error(cli, "decode", path, "--current-scale", "0")
    with pytest.raises(hwfoc.SettingsError) as e:
        hwfoc.read(path, pole_pairs=0)
    assert str(e.value) == cli_error(cli, "decode", path, "--pole-pairs", "0")
    with pytest.raises(ValueError):
        hwfoc.read(path, esc=256)
    with pytest.raises(TypeError):
        hwfoc.read(path, esc="zero")
    with pytest.raises(TypeError):
        hwfoc.read(path, start="yesterday")


def test_a_window_that_holds_no_frame_warns_as_the_command_does(cli, sim_dir):
    path = sim_dir / "three.pcapng"
    # An hour after the data, in Unix seconds (a bare number more than a year before the data is
    # refused by the command, which suggests +N).
    after = int(hwfoc.read(path).column("t_s")[0].as_py()) + 3600
    start, end = after, after + 100
    with pytest.warns(hwfoc.HwfocWarning) as caught:
        table = hwfoc.read(path, start=start, end=end)
    assert table.num_rows == 0
    _, err, _ = run_cli(cli, "decode", path, "--from", start, "--to", end)
    assert f"no frame in the time window (from={start} to={end})" in err
    assert [f"hwfoc: warning: {w.message}" for w in caught] == err.splitlines()
    with pytest.warns(hwfoc.HwfocWarning) as scanned:
        assert sum(b.num_rows for b in hwfoc.scan(path, start=start, end=end)) == 0
    assert [str(w.message) for w in scanned] == [str(w.message) for w in caught]


def test_a_window_on_raw_bytes_is_refused(cli, sim_dir):
    path = sim_dir / "one.bin"
    with pytest.raises(hwfoc.InputError) as e:
        hwfoc.read(path, start=1)
    assert str(e.value) == (
        f"start/end select frames by time, but {path} is raw bytes without receive times: "
        "read a recording or a logic-analyser CSV, or leave out start and end"
    )
    assert "--from/--to select frames by time" in cli_error(cli, "decode", path, "--from", "1")


def test_bad_inputs_raise_the_commands_errors(cli, tmp_path):
    missing = tmp_path / "missing.bin"
    empty = tmp_path / "empty.bin"
    empty.write_bytes(b"")
    classic = tmp_path / "old.pcap"
    classic.write_bytes(bytes([0xD4, 0xC3, 0xB2, 0xA1]) + bytes(20))
    bad_csv = tmp_path / "bad.csv"
    bad_csv.write_text("Time [s],Value,Parity Error,Framing Error\n0.1,0x9B,,\n0.2,zz,,\n")
    for path in (missing, empty, classic, tmp_path, bad_csv):
        with pytest.raises(hwfoc.InputError) as e:
            hwfoc.read(path)
        assert str(e.value) == cli_error(cli, "decode", path), path
        assert isinstance(e.value, hwfoc.HwfocError)
    with pytest.raises(hwfoc.InputError) as e:
        hwfoc.summary(missing)
    assert str(e.value) == cli_error(cli, "summary", missing)


def test_text_mode_file_objects_and_other_types_are_refused(sim_dir):
    with pytest.raises(hwfoc.InputError, match="binary mode"):
        hwfoc.read(io.StringIO("not bytes"))
    with pytest.raises(TypeError, match="cannot read a int"):
        hwfoc.read(3)
    with pytest.raises(TypeError):
        hwfoc.read([])


def test_garbage_and_other_protocols_warn_as_the_command_does(cli, tmp_path):
    rng = np.random.default_rng(5)
    garbage = tmp_path / "garbage.bin"
    garbage.write_bytes(rng.integers(0, 256, 20000, dtype=np.uint8).tobytes())
    # A DataLink-like stream (another protocol): 0x9B headers that never make a HW-FOC frame.
    other = tmp_path / "other.bin"
    other.write_bytes(bytes([0x9B, 0x30, 0x01, 0x22] + list(range(40))) * 200)
    notes = tmp_path / "notes.txt"
    notes.write_text("Notes of the bench run: motor 2 sounded rough at 60 %.\n" * 50)
    for path in (garbage, other, notes):
        _, err, code = run_cli(cli, "decode", path, check=False)
        assert code == 1, err
        # The command warns, then fails (no data frame in any input); Python warns alike, then
        # raises the command's error, never an empty table.
        warned = [line for line in err.splitlines() if line.startswith("hwfoc: warning: ")]
        failed = err.splitlines()[-1]
        assert failed.startswith("hwfoc: no data frame in any input"), err
        with pytest.warns(hwfoc.HwfocWarning) as caught, pytest.raises(hwfoc.InputError) as e:
            hwfoc.read(path)
        assert [f"hwfoc: warning: {w.message}" for w in caught] == warned
        assert f"hwfoc: {e.value}" == failed
        # scan warns alike, once its inputs are read, then raises.
        with pytest.warns(hwfoc.HwfocWarning) as scanned, pytest.raises(hwfoc.InputError) as e:
            for _ in hwfoc.scan(path):
                pass
        assert [str(w.message) for w in scanned] == [str(w.message) for w in caught]
        assert f"hwfoc: {e.value}" == failed
        with pytest.raises(hwfoc.InputError) as e:
            hwfoc.summary(path)
        assert str(e.value) == cli_error(cli, "summary", path)


def test_truncated_recording_reads_what_is_there(cli, sim_dir, tmp_path, capfd):
    data = (sim_dir / "three.pcapng").read_bytes()
    cut = tmp_path / "cut.pcapng"
    cut.write_bytes(data[: len(data) * 2 // 3 + 5])
    # The damage is a warning a caller can catch or filter, with the command's words, and
    # nothing is printed behind the caller's back.
    with pytest.warns(hwfoc.HwfocWarning) as caught:
        table = hwfoc.read(cut)
    assert capfd.readouterr().err == ""
    _, err, _ = run_cli(cli, "decode", cut)
    damage = [line for line in err.splitlines() if "stopped at byte" in line]
    assert len(damage) == 1
    assert [f"hwfoc: warning: {w.message}" for w in caught] == damage
    for call in (lambda: list(hwfoc.scan(cut)), lambda: hwfoc.summary(cut)):
        with pytest.warns(hwfoc.HwfocWarning, match="stopped at byte"):
            call()
    assert capfd.readouterr().err == ""
    records = cli_records(cli, cut)
    assert 0 < len(records)
    assert_same_records(table, records)


def test_random_bytes_never_crash_the_interpreter(tmp_path):
    # In a child process, so that a crash would show as its exit status, not end the tests.
    script = r"""
import io, sys, warnings
import numpy as np
import hwfoc
warnings.simplefilter("ignore")
rng = np.random.default_rng(11)
header = bytes.fromhex("0a0d0d0a")
for k in range(300):
    n = int(rng.integers(1, 3000))
    data = rng.integers(0, 256, n, dtype=np.uint8).tobytes()
    if k % 3 == 0:
        data = header + data
    if k % 3 == 1:
        data = b"Time [s],Value,Parity Error,Framing Error\n" + data
    for call in (lambda: hwfoc.read(data), lambda: hwfoc.summary(data), lambda: list(hwfoc.scan(data))):
        try:
            call()
        except hwfoc.HwfocError:
            pass
    d = hwfoc.Decoder()
    d.feed(data)
    d.finish()
print("ok")
"""
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-3000:]
    assert p.stdout.strip() == "ok"
    assert "panicked" not in p.stderr


def test_polars_and_pandas_take_the_table(sim_dir):
    import pandas as pd
    import polars as pl

    table = hwfoc.read(sim_dir / "three.pcapng")
    df = pl.from_arrow(table)
    assert df.height == table.num_rows
    assert df.schema["esc"] == pl.UInt8 and df.schema["faults"] == pl.List(pl.String)
    hot = df.group_by("esc").agg(pl.col("mos_temp_c").max()).sort("esc")
    assert hot.height == 3
    pdf = table.to_pandas()
    # Record schema 2: packet uint32 (nullable: pandas' nullable or plain integer type), protocol
    # a categorical.
    assert str(pdf["packet"].dtype).lower() == "uint32"
    assert str(pdf["protocol"].dtype) == "category"
    assert df.schema["protocol"] == pl.Categorical or isinstance(df.schema["protocol"], (pl.Categorical, pl.Enum))
    assert pdf["mos_temp_c"].max() == pytest.approx(float(pa.compute.max(table.column("mos_temp_c")).as_py()))
    assert isinstance(pdf, pd.DataFrame)


def _hub_bytes(cli):
    """DataLink V2 frames of eight virtual ESCs: what `hwfoc bridge --datalink` writes to a
    pseudo-terminal in a second and a half."""
    import select
    import time

    master, slave = os.openpty()
    try:
        bridge = subprocess.Popen(
            [cli, "bridge", "--sim", "8", "--datalink", os.ttyname(slave), "--duration", "1.5",
             "--quiet", "--no-config"],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        got = b""
        until = time.time() + 30
        while time.time() < until:
            ready, _, _ = select.select([master], [], [], 0.2)
            if ready:
                got += os.read(master, 65536)
            elif bridge.poll() is not None:
                break
        assert bridge.wait(timeout=10) == 0, bridge.stderr.read()
        return got
    finally:
        os.close(master)
        os.close(slave)


@pytest.fixture(scope="module")
def mixed(cli, tmp_path_factory):
    """ESC frames, hub frames, ESC frames: the three parts' bytes and the whole."""
    d = tmp_path_factory.mktemp("mixed")
    first = simulate(cli, d / "a.bin", "--seed", "1", "--duration", "3").read_bytes()
    last = simulate(cli, d / "b.bin", "--seed", "2", "--duration", "3").read_bytes()
    hub = _hub_bytes(cli)
    return first, hub, last, first + hub + last


def _rows(table):
    return [(r["esc"], r["packet"], r["voltage_v"]) for r in table.to_pylist()]


def test_a_forced_protocol_reads_its_frames_only(mixed):
    first, hub, last, whole = mixed
    escs = hwfoc.read(first + last)
    hubs = hwfoc.read(hub)
    assert escs.num_rows > 10 and set(hubs.column("esc").to_pylist()) == set(range(8))
    forced_esc = hwfoc.read(whole, protocol="hw-foc")
    assert _rows(forced_esc) == _rows(escs)
    forced_hub = hwfoc.read(whole, protocol="datalink")
    assert _rows(forced_hub) == _rows(hubs)
    # The protocol column says which frames were whose: an ESC's own, or a hub's channels;
    # the columns no protocol read today carries are null.
    assert set(escs.column("protocol").to_pylist()) == {"hw-foc"}
    assert set(hubs.column("protocol").to_pylist()) == {"datalink"}
    assert pa.types.is_dictionary(hubs.schema.field("protocol").type)
    assert pa.types.is_uint32(hubs.schema.field("packet").type)
    whole_table = hwfoc.read(whole)
    assert set(whole_table.column("protocol").to_pylist()) == {"hw-foc", "datalink"}
    for name in ("motor_temp_c", "bec_temp_c", "bec_voltage_v", "bec_current_a"):
        assert whole_table.column(name).null_count == whole_table.num_rows, name
    assert hwfoc.read(whole).num_rows == escs.num_rows + hubs.num_rows
    # The other protocol's bytes are skipped bytes; scan and the decoder read alike.
    link = hwfoc.summary(whole, protocol="hw-foc")["escs"][0]["link"]
    assert link["bytes_skipped"] >= len(hub)
    scanned = pa.Table.from_batches(list(hwfoc.scan(whole, protocol="datalink")))
    assert _rows(scanned) == _rows(hubs)
    decoder = hwfoc.Decoder(protocol="datalink")
    fed = [decoder.feed(whole[i:i + 100]) for i in range(0, len(whole), 100)] + [decoder.finish()]
    assert _rows(pa.Table.from_batches(fed)) == _rows(hubs)
    assert decoder.stats["bytes_skipped"] == len(first) + len(last)


def test_esc_frames_then_hub_frames_in_one_block_are_the_commands(cli, mixed, tmp_path):
    # A raw ESC input's frames are kept as HW-FOC frames until another protocol's frame comes
    # into the same block of rows: then all of the block is converted frame by frame.
    first, hub, last, whole = mixed
    files = [tmp_path / "a.bin", tmp_path / "hub.bin", tmp_path / "b.bin"]
    for path, data in zip(files, (first, hub, last)):
        path.write_bytes(data)
    table = hwfoc.read(files)
    assert set(table.column("protocol").to_pylist()) == {"hw-foc", "datalink"}
    assert_same_records(table, cli_records(cli, *files))
    # The same in one input: ESC frames, then the hub's, then ESC frames again.
    (tmp_path / "whole.bin").write_bytes(whole)
    assert_same_records(hwfoc.read(whole), cli_records(cli, tmp_path / "whole.bin"))


def test_a_forced_protocol_that_finds_nothing_warns_with_its_advice(mixed):
    first = mixed[0]
    # Its bytes are HW-FOC frames: the warning says so, not the baud rate and the wiring.
    with pytest.warns(hwfoc.HwfocWarning, match=r"no valid DataLink V2 frames: these bytes are hw-foc frames "
                                                 r"\(try --protocol hw-foc, or leave --protocol out\)"), \
            pytest.raises(hwfoc.InputError, match="no data frame in any input"):
        hwfoc.read(first, protocol="datalink")


def test_protocol_names_and_their_defaults():
    assert hwfoc.PROTOCOLS == ("hw-foc", "datalink", "hw-v4", "hw-v3", "hw5", "hw-can", "dronecan")
    for f in (hwfoc.read, hwfoc.scan, hwfoc.summary, hwfoc.Decoder, hwfoc.open_ports):
        assert inspect.signature(f).parameters["protocol"].default is None, f
    for call in (lambda: hwfoc.read(b"", protocol="hw4"), lambda: hwfoc.scan(b"", protocol="v3"),
                 lambda: hwfoc.summary(b"", protocol="dl"), lambda: hwfoc.Decoder(protocol="x"),
                 lambda: hwfoc.open_ports(["/dev/null"], protocol="x")):
        with pytest.raises(ValueError, match=r'protocol: ".*" is not a protocol: give one of "hw-foc", '
                                             r'"datalink", "hw-v4", "hw-v3", "hw5", "hw-can", "dronecan"'):
            call()
    # Every protocol's name is taken (any case), by every function; a CAN protocol's too (it
    # keeps a bus's records of that protocol; serial bytes give nothing, which fails as the
    # command does).
    for name in hwfoc.PROTOCOLS + ("HW5", "Hw-V4", "DroneCAN"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", hwfoc.HwfocWarning)
            for call in (hwfoc.read, lambda *a, **k: list(hwfoc.scan(*a, **k)), hwfoc.summary):
                with pytest.raises(hwfoc.InputError, match="no data frame in any input"):
                    call(b"\0", protocol=name)
        assert hwfoc.Decoder(protocol=name).finish().num_rows == 0
