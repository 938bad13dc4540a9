"""Every serial format hwfoc reads, through the package: the two real Platinum captures (V4 and
V3) and an HW5 stream through read, scan, summary, the Decoder, Dask and Spark; the protocol
column, the columns a format does not carry (null), HW5's fault names, and the setting
``v4_volts_per_step``."""

import csv
import inspect
import json
import os
import struct
import sys

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest

import hwfoc
from conftest import ROOT, assert_same_records, cli_records, run_cli

CAPTURES = ROOT / "testdata" / "captures"
V4 = CAPTURES / "platinum-v4.csv"
V3 = CAPTURES / "platinum-pro-v3.csv"

MEASUREMENTS = [
    "throttle_in_pct", "throttle_out_pct", "erpm", "rpm", "voltage_v", "current_a",
    "phase_current_a", "mos_temp_c", "cap_temp_c", "motor_temp_c", "bec_temp_c",
    "bec_voltage_v", "bec_current_a",
]
# The columns each format's records leave null, whatever the frame (hwfoc::Protocol::carries;
# status and faults where a format has no fault word; packet where it has no counter).
NOT_CARRIED = {
    "hw-v4": {"phase_current_a", "motor_temp_c", "bec_temp_c", "bec_voltage_v", "bec_current_a",
              "status", "faults"},
    "hw-v3": {"voltage_v", "current_a", "phase_current_a", "mos_temp_c", "cap_temp_c",
              "motor_temp_c", "bec_temp_c", "bec_voltage_v", "bec_current_a", "status", "faults"},
    "hw5": {"packet", "throttle_out_pct", "phase_current_a", "cap_temp_c"},
}


def _nulls_where_not_carried(table, protocol):
    for name in NOT_CARRIED[protocol]:
        assert table.column(name).null_count == table.num_rows, (protocol, name)
    # Every other quantity has a value in some record.
    for name in set(MEASUREMENTS) - NOT_CARRIED[protocol]:
        if not (protocol == "hw-v4" and name in ("current_a", "cap_temp_c")):
            assert table.column(name).null_count < table.num_rows, (protocol, name)


def _capture_bytes(path):
    """The bytes of a logic-analyser CSV export, with their times."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))[1:]
    return bytes(int(r[1], 16) for r in rows), [float(r[0]) for r in rows]


# ---- the Platinum captures -------------------------------------------------------------------


def test_the_platinum_v4_capture():
    table = hwfoc.read(V4)
    assert table.num_rows == 297
    assert set(table.column("protocol").to_pylist()) == {"hw-v4"}
    assert table.column("packet").to_pylist() == list(range(817, 1114))
    _nulls_where_not_carried(table, "hw-v4")
    volts = table.column("voltage_v")
    assert volts.null_count == 0
    assert round(pc.min(volts).as_py(), 2) == 11.87
    assert round(pc.max(volts).as_py(), 2) == 12.02
    assert pc.max(table.column("throttle_in_pct")).as_py() == 100.0
    # No current sensor (the info frame's I1 is 0): no current at all.
    assert table.column("current_a").null_count == table.num_rows


def test_the_platinum_pro_v3_capture():
    table = hwfoc.read(V3)
    assert table.num_rows == 699
    assert set(table.column("protocol").to_pylist()) == {"hw-v3"}
    assert table.column("packet").to_pylist() == list(range(0, 699))
    _nulls_where_not_carried(table, "hw-v3")
    # Before the motor turns the period field holds the ESC's placeholder: no speed.
    erpm = table.column("erpm").to_pylist()
    assert erpm[0] is None and any(e is not None and e > 0 for e in erpm)
    assert pc.max(table.column("throttle_in_pct")).as_py() <= 100.0


@pytest.mark.parametrize("capture,protocol", [(V4, "hw-v4"), (V3, "hw-v3")], ids=["v4", "v3"])
def test_scan_and_the_decoder_read_as_read(capture, protocol):
    table = hwfoc.read(capture)
    scanned = pa.Table.from_batches(list(hwfoc.scan(capture, batch_rows=100)))
    assert scanned.equals(table.replace_schema_metadata(scanned.schema.metadata))
    assert hwfoc.read(capture, protocol=protocol).equals(table)
    data, times = _capture_bytes(capture)
    decoder = hwfoc.Decoder()
    batches = [decoder.feed(data[i:i + 37], times[i]) for i in range(0, len(data), 37)]
    fed = pa.Table.from_batches(batches + [decoder.finish()])
    keys = ["protocol", "packet", "throttle_in_pct", "erpm", "voltage_v", "mos_temp_c"]
    assert fed.select(keys).to_pylist() == table.select(keys).to_pylist()
    assert decoder.stats["frames"] == table.num_rows


@pytest.mark.parametrize("capture,protocol,other", [(V4, "hw-v4", "hw-v3"), (V3, "hw-v3", "hw-v4")],
                         ids=["v4", "v3"])
def test_the_protocol_forced_reads_that_format_only(capture, protocol, other):
    assert hwfoc.read(capture, protocol=protocol).num_rows > 0
    with pytest.warns(hwfoc.HwfocWarning), pytest.raises(hwfoc.InputError, match="no data frame"):
        hwfoc.read(capture, protocol=other)


@pytest.mark.parametrize("capture", [V4, V3], ids=["v4", "v3"])
def test_the_captures_summary_is_the_commands(cli, capture):
    out, _, _ = run_cli(cli, "summary", "--json", capture)
    got = hwfoc.summary(capture)
    assert got == json.loads(out)
    esc = got["escs"][0]
    if capture == V4:
        assert (esc["protocol"], esc["frames"], esc["info_frames"]) == ("hw-v4", 297, 26)
        assert esc["link"]["rejected_candidates"] == 0 and esc["link"]["lost_packets"] == 0
        (info,) = esc["info"]
        assert info["adopted"] and info["full_scale"] == 1000
    else:
        assert (esc["protocol"], esc["frames"]) == ("hw-v3", 699)
        assert esc["link"]["rejected_candidates"] == 0


# ---- v4_volts_per_step -----------------------------------------------------------------------


def test_v4_volts_per_step_converts_v4_voltages_until_the_info_frame(cli, tmp_path):
    default = hwfoc.read(V4)
    hv = hwfoc.read(V4, settings={"v4_volts_per_step": "hv"})
    assert_same_records(hv, cli_records(cli, V4, "--v4-volts-per-step", "hv"))
    assert hv.schema.metadata[b"v4_volts_per_step"] == b"11/650"
    assert default.schema.metadata[b"v4_volts_per_step"] == b"8/910"
    before, after = default.column("voltage_v").to_pylist(), hv.column("voltage_v").to_pylist()
    # The first frames come before an info frame is adopted (two identical copies): 11/650 V
    # per step there; the info frame's 8/910 after it, whatever the setting.
    changed = [i for i, (a, b) in enumerate(zip(before, after)) if a != b]
    assert changed and changed == list(range(len(changed))), changed
    assert len(changed) < 10
    for i in changed:
        assert after[i] == pytest.approx(before[i] * (11 / 650) / (8 / 910), rel=1e-6)
    # "N/D" as the command takes it; "low" is the default.
    assert hwfoc.read(V4, settings={"v4_volts_per_step": "11/650"}).equals(hv)
    assert hwfoc.read(V4, settings={"v4_volts_per_step": "low"}).equals(default)
    # Other formats are not changed by it, but their metadata says it.
    assert hwfoc.read(V3, settings={"v4_volts_per_step": "hv"}).drop_columns([]).column("rpm").equals(
        hwfoc.read(V3).column("rpm"))
    # In the Parquet metadata of the command's export, and the summary's settings.
    out = tmp_path / "v4.parquet"
    run_cli(cli, "decode", "--format", "parquet", "-o", out, V4, "--v4-volts-per-step", "hv")
    assert pq.read_metadata(out).metadata[b"v4_volts_per_step"] == b"11/650"
    file_meta = {k: v for k, v in pq.read_metadata(out).metadata.items() if k != b"ARROW:schema"}
    assert hv.schema.metadata == file_meta
    assert hwfoc.summary(V4, settings={"v4_volts_per_step": "hv"})["settings"]["v4_volts_per_step"] == "11/650"
    scanned = next(iter(hwfoc.scan(V4, settings={"v4_volts_per_step": "hv"})))
    assert scanned.schema.metadata[b"v4_volts_per_step"] == b"11/650"
    assert hwfoc.record_schema(settings={"v4_volts_per_step": "9/700"}).metadata[b"v4_volts_per_step"] == b"9/700"
    decoder = hwfoc.Decoder(settings={"v4_volts_per_step": "hv"})
    assert decoder.schema.metadata[b"v4_volts_per_step"] == b"11/650"
    data, _ = _capture_bytes(V4)
    fed = pa.Table.from_batches([decoder.feed(data), decoder.finish()])
    assert fed.column("voltage_v").to_pylist() == after


@pytest.mark.parametrize("bad", ["9/0", "0/910", "8", "x", "", "8/910/1", "70000/1"])
def test_a_bad_v4_volts_per_step_is_a_value_error_naming_it(bad):
    for call in (lambda: hwfoc.read(V4, settings={"v4_volts_per_step": bad}),
                 lambda: hwfoc.scan(V4, settings={"v4_volts_per_step": bad}),
                 lambda: hwfoc.summary(V4, settings={"v4_volts_per_step": bad}),
                 lambda: hwfoc.record_schema(settings={"v4_volts_per_step": bad}),
                 lambda: hwfoc.Decoder(settings={"v4_volts_per_step": bad}),
                 lambda: hwfoc.open_ports(["/dev/null"], settings={"v4_volts_per_step": bad})):
        with pytest.raises(ValueError, match=r"^v4_volts_per_step: .*volts per step must be N/D"):
            call()


def test_the_default_v4_volts_per_step_is_the_librarys():
    assert hwfoc.DEFAULT_SETTINGS == {"v4_volts_per_step": "8/910"}
    assert hwfoc.record_schema().metadata[b"v4_volts_per_step"] == b"8/910"
    for f in (hwfoc.read, hwfoc.scan, hwfoc.summary, hwfoc.record_schema, hwfoc.Decoder, hwfoc.open_ports):
        params = inspect.signature(f).parameters
        assert params["settings"].default is None, f
        # The formats' settings are keys of `settings=`, not arguments of their own.
        assert not set(params) & set(hwfoc.DEFAULT_SETTINGS), f


def test_format_settings_are_read_by_their_descriptions_keys():
    # Every key of the descriptions, at its default, changes nothing; `-` and `_` alike.
    assert hwfoc.read(V4, settings=dict(hwfoc.DEFAULT_SETTINGS)).equals(hwfoc.read(V4))
    hv = hwfoc.read(V4, settings={"v4_volts_per_step": "hv"})
    assert hwfoc.read(V4, settings={"v4-volts-per-step": "hv"}).equals(hv)


def test_an_unknown_format_setting_is_a_settings_error_listing_the_keys():
    keys = " ".join(hwfoc.DEFAULT_SETTINGS)
    for call in (lambda s: hwfoc.read(V4, settings=s),
                 lambda s: hwfoc.scan(V4, settings=s),
                 lambda s: hwfoc.summary(V4, settings=s),
                 lambda s: hwfoc.record_schema(settings=s),
                 lambda s: hwfoc.Decoder(settings=s),
                 lambda s: hwfoc.CanDecoder(settings=s),
                 lambda s: hwfoc.open_ports(["/dev/null"], settings=s)):
        with pytest.raises(hwfoc.SettingsError) as e:
            call({"v4_volts": "hv"})
        assert str(e.value) == f'settings: "v4_volts": no format has this setting; the settings are: {keys}'


# ---- HW5 -------------------------------------------------------------------------------------


def crc16_modbus(data: bytes) -> int:
    crc = 0xFFFF
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return crc


HW5_BITS = ["motor_locked", "over_temperature", "throttle_not_zero_at_start", "throttle_signal_lost",
            "over_current", "low_voltage", "input_voltage_error", "motor_connection_error"]


def hw5_frame(throttle=0, fault=0, erpm_raw=0, voltage_raw=0, current_raw=0, esc_temp=0, bec_temp=0,
              motor_temp=0, bec_voltage_raw=0, bec_current_raw=0):
    """An HW5 telemetry frame as an ESC sends it (docs/HW5-AND-CAN.md): 32 bytes, fields
    little-endian, CRC-16/MODBUS low byte first."""
    body = (bytes([0xFE, 0x01, 0x00, 0x03, 0x30, 0x5C, 0x17, 0x06, 0x00, throttle, 0, 0, fault])
            + struct.pack("<HHH", erpm_raw, voltage_raw, current_raw)
            + bytes([esc_temp, bec_temp, motor_temp, bec_voltage_raw, bec_current_raw])
            + b"\xff" * 6)
    return body + struct.pack("<H", crc16_modbus(body))


def test_the_hw5_helper_writes_the_vectors_frames():
    # The helper agrees with the committed vectors (made by crcmod from the spec).
    lines = (ROOT / "testdata" / "hw5" / "vectors.txt").read_text().splitlines()
    checked = 0
    for line in lines:
        words = line.split()
        if words and words[0] == "crc":
            data = b"" if words[1] == "-" else bytes.fromhex(words[1])
            assert crc16_modbus(data) == int(words[2], 16), line
        elif words and words[0] == "telemetry":
            v = dict(w.split("=", 1) for w in words[2:])
            if v["unknown"] != "0000":
                continue
            fields = {k: int(v[k]) for k in ("throttle", "fault", "erpm_raw", "voltage_raw", "current_raw",
                                             "esc_temp", "bec_temp", "motor_temp", "bec_voltage_raw",
                                             "bec_current_raw")}
            assert hw5_frame(**fields) == bytes.fromhex(words[1]), line
            checked += 1
    assert checked >= 3


HW5_FRAMES = [
    dict(throttle=0, voltage_raw=504, esc_temp=30, bec_temp=31, motor_temp=29, bec_voltage_raw=84,
         bec_current_raw=3),
    dict(throttle=62, erpm_raw=900, voltage_raw=498, current_raw=357, esc_temp=48, bec_temp=41, motor_temp=55,
         bec_voltage_raw=84, bec_current_raw=12),
    dict(throttle=80, fault=0b0010_1000, erpm_raw=1200, voltage_raw=455, current_raw=512, esc_temp=70,
         bec_temp=45, motor_temp=66, bec_voltage_raw=83, bec_current_raw=15),
    dict(throttle=0, fault=0b1000_0001, voltage_raw=470, esc_temp=71, bec_temp=46, motor_temp=60,
         bec_voltage_raw=84, bec_current_raw=2),
]


@pytest.fixture(scope="module")
def hw5_stream():
    frames = [hw5_frame(**HW5_FRAMES[i % len(HW5_FRAMES)]) for i in range(40)]
    # Line noise between two frames, and a frame with a bad CRC, are skipped.
    bad = bytearray(hw5_frame(**HW5_FRAMES[1]))
    bad[20] ^= 0x01
    return b"".join(frames[:20]) + b"\x00\x13\xfe\x01" + bytes(bad) + b"".join(frames[20:])


def test_an_hw5_stream(cli, hw5_stream, tmp_path):
    table = hwfoc.read(hw5_stream)
    assert table.num_rows == 40
    assert set(table.column("protocol").to_pylist()) == {"hw5"}
    _nulls_where_not_carried(table, "hw5")
    rows = table.to_pylist()
    for i, row in enumerate(rows):
        v = dict.fromkeys(["fault", "erpm_raw", "current_raw"], 0) | HW5_FRAMES[i % len(HW5_FRAMES)]
        assert row["throttle_in_pct"] == v["throttle"]
        assert row["erpm"] == v["erpm_raw"] * 10
        assert row["voltage_v"] == pytest.approx(v["voltage_raw"] / 10)
        assert row["current_a"] == pytest.approx(v["current_raw"] / 10)
        assert (row["mos_temp_c"], row["bec_temp_c"], row["motor_temp_c"]) == (
            v["esc_temp"], v["bec_temp"], v["motor_temp"])
        assert row["bec_voltage_v"] == pytest.approx(v["bec_voltage_raw"] / 10)
        assert row["bec_current_a"] == pytest.approx(v["bec_current_raw"] / 10)
        assert row["status"] == v["fault"]
        # HW5's faults by HW5's names, in bit order.
        assert row["faults"] == [HW5_BITS[b] for b in range(8) if v["fault"] >> b & 1]
    assert rows[2]["faults"] == ["throttle_signal_lost", "low_voltage"]
    assert rows[3]["faults"] == ["motor_locked", "motor_connection_error"]
    # As the command reads the same bytes.
    path = tmp_path / "hw5.bin"
    path.write_bytes(hw5_stream)
    assert_same_records(table, cli_records(cli, path))
    assert hwfoc.read(path, protocol="hw5").equals(hwfoc.read(path))
    # The decoder, fed a few bytes at a time, and scan read alike.
    decoder = hwfoc.Decoder(protocol="hw5")
    fed = [decoder.feed(hw5_stream[i:i + 7]) for i in range(0, len(hw5_stream), 7)] + [decoder.finish()]
    assert pa.Table.from_batches(fed).to_pylist() == rows
    assert decoder.stats["frames"] == 40
    assert pa.Table.from_batches(list(hwfoc.scan(hw5_stream))).to_pylist() == rows


def test_an_hw5_summary(cli, hw5_stream, tmp_path):
    path = tmp_path / "hw5.bin"
    path.write_bytes(hw5_stream)
    got = hwfoc.summary(path)
    out, _, _ = run_cli(cli, "summary", "--json", path)
    assert got == json.loads(out)
    esc = got["escs"][0]
    assert (esc["protocol"], esc["frames"]) == ("hw5", 40)
    # No counter: HW5's loss is not known from the bytes alone.
    assert esc["link"]["lost_packets"] is None and esc["link"]["delivery_ratio"] is None
    assert esc["link"]["checksum_failures"] == 1
    assert {"throttle_signal_lost", "low_voltage", "motor_locked", "motor_connection_error"} <= set(
        esc["faults"])


# ---- Dask and Spark --------------------------------------------------------------------------


def _fleet_of_formats(tmp_path, hw5_stream):
    hw5 = tmp_path / "hw5.bin"
    hw5.write_bytes(hw5_stream)
    return [str(V4), str(V3), str(hw5)]


def test_dask_reads_every_format(tmp_path, hw5_stream):
    import hwfoc.dask

    paths = _fleet_of_formats(tmp_path, hw5_stream)
    ddf = hwfoc.dask.read(paths, path_column="recording", frame_column="frame",
                          settings={"v4_volts_per_step": "hv"})
    df = ddf.compute()
    counts = df.groupby("recording")["esc"].size().to_dict()
    assert counts == {paths[0]: 297, paths[1]: 699, paths[2]: 40}
    by_file = {p: set(df[df["recording"] == p]["protocol"].astype(str)) for p in paths}
    assert by_file == {paths[0]: {"hw-v4"}, paths[1]: {"hw-v3"}, paths[2]: {"hw5"}}
    v4 = df[df["recording"] == paths[0]]
    assert list(v4["packet"]) == list(range(817, 1114))
    assert v4["throttle_in_pct"].max() == 100.0
    # The setting reached the partitions: the first V4 frames read under 11/650 V per step.
    assert v4["voltage_v"].iloc[0] == pytest.approx(1356 * 11 / 650, rel=1e-6)
    assert df[df["recording"] == paths[1]]["voltage_v"].isna().all()
    hw5 = df[df["recording"] == paths[2]]
    assert hw5["packet"].isna().all() and hw5["bec_voltage_v"].notna().all()
    faults = hw5["faults"].tolist()
    assert list(faults[2]) == ["throttle_signal_lost", "low_voltage"]
    per_esc = hwfoc.dask.esc_aggregates(ddf).compute()
    assert dict(zip(per_esc["recording"], per_esc["rows"])) == counts


@pytest.fixture(scope="module")
def spark():
    os.environ.setdefault("PYSPARK_PYTHON", sys.executable)
    os.environ.setdefault("PYSPARK_DRIVER_PYTHON", sys.executable)
    from pyspark.sql import SparkSession

    session = (
        SparkSession.builder.master("local[2]")
        .appName("hwfoc-protocols")
        .config("spark.ui.enabled", "false")
        .config("spark.sql.shuffle.partitions", "4")
        .config("spark.sql.execution.arrow.pyspark.enabled", "true")
        .getOrCreate()
    )
    yield session
    session.stop()


def test_spark_reads_every_format(spark, tmp_path, hw5_stream):
    import hwfoc.spark

    paths = _fleet_of_formats(tmp_path, hw5_stream)
    df = hwfoc.spark.read(spark, paths, path_column="recording", frame_column="frame",
                          settings={"v4_volts_per_step": "hv"})
    rows = df.collect()
    by_file = {}
    for r in rows:
        by_file.setdefault(r["recording"], []).append(r)
    assert {p: len(r) for p, r in by_file.items()} == {paths[0]: 297, paths[1]: 699, paths[2]: 40}
    assert {p: {r["protocol"] for r in rs} for p, rs in by_file.items()} == {
        paths[0]: {"hw-v4"}, paths[1]: {"hw-v3"}, paths[2]: {"hw5"}}
    v4 = sorted(by_file[paths[0]], key=lambda r: r["frame"])
    assert [r["packet"] for r in v4] == list(range(817, 1114))
    assert max(r["throttle_in_pct"] for r in v4) == 100.0
    assert v4[0]["voltage_v"] == pytest.approx(1356 * 11 / 650, rel=1e-6)
    v3 = sorted(by_file[paths[1]], key=lambda r: r["frame"])
    assert [r["packet"] for r in v3] == list(range(0, 699))
    assert all(r["voltage_v"] is None for r in v3)
    hw5 = sorted(by_file[paths[2]], key=lambda r: r["frame"])
    assert all(r["packet"] is None and r["bec_voltage_v"] is not None for r in hw5)
    assert list(hw5[2]["faults"]) == ["throttle_signal_lost", "low_voltage"]
    schema = hwfoc.spark.spark_schema("recording", "frame", settings={"v4_volts_per_step": "hv"})
    assert df.schema == schema
    # `time` (record schema 4): a Spark timestamp, null exactly where `t_s` is.
    from pyspark.sql import types as T

    assert df.schema["time"].dataType == T.TimestampType()
    assert all((r["time"] is None) == (r["t_s"] is None) for r in rows)


# ---- the CAN protocols and what a forced protocol finds --------------------------------------

CAN_LOG = ROOT / "testdata" / "dronecan" / "can-bus.log"


def test_the_can_protocols_are_listed_and_filter_a_bus():
    assert hwfoc.PROTOCOLS[-2:] == ("hw-can", "dronecan")
    assert hwfoc.read(CAN_LOG).num_rows == 58
    for protocol, rows, other, left in [("hw-can", 39, "dronecan", 19), ("dronecan", 19, "hw-can", 39)]:
        with pytest.warns(hwfoc.HwfocWarning, match=f"{left} {other} records left out"):
            table = hwfoc.read(CAN_LOG, protocol=protocol)
        assert table.num_rows == rows
        assert set(table.column("protocol").to_pylist()) == {protocol}
    with pytest.warns(hwfoc.HwfocWarning, match="39 hw-can records and 19 dronecan records"), \
            pytest.raises(hwfoc.InputError, match="no data frame"):
        hwfoc.read(CAN_LOG, protocol="hw5")


def test_a_forced_protocol_names_the_format_the_bytes_are():
    with pytest.warns(hwfoc.HwfocWarning, match="these bytes are hw-v4 frames"), \
            pytest.raises(hwfoc.InputError, match="no data frame"):
        hwfoc.read(V4, protocol="hw5")
    with pytest.warns(hwfoc.HwfocWarning, match="not CAN frames but hw-v4 frames"), \
            pytest.raises(hwfoc.InputError, match="no data frame"):
        hwfoc.read(V4, protocol="hw-can")


def test_a_can_protocol_on_a_serial_port_is_a_value_error():
    with pytest.raises(ValueError, match="reads CAN buses"):
        hwfoc.open_ports(["/dev/ttyUSB_hwfoc_missing"], protocol="dronecan")


# ---- link figures ------------------------------------------------------------------------------

# The link figures under their one set of names (hwfoc-records' LinkStats::figures): a decoder's
# stats and the summary's `link` give the same, None where the format does not count one.
FIGURES = ("checksum_failures", "rejected_candidates", "lost_packets", "duplicate_packets",
           "restarts", "bytes_skipped", "delivery_ratio")


@pytest.mark.parametrize("capture,protocol", [(V4, "hw-v4"), (V3, "hw-v3")], ids=["v4", "v3"])
def test_a_decoders_link_figures_are_the_summarys(capture, protocol, tmp_path):
    data, _ = _capture_bytes(capture)
    path = tmp_path / "raw.bin"
    path.write_bytes(data)
    link = hwfoc.summary(path)["escs"][0]["link"]
    # No checksum: its rejected candidates are counted instead, and its packets are numbered.
    assert link["checksum_failures"] is None and link["rejected_candidates"] == 0
    assert link["lost_packets"] is not None and link["delivery_ratio"] == 1.0
    for forced in (None, protocol):
        decoder = hwfoc.Decoder(protocol=forced)
        for i in range(0, len(data), 37):
            decoder.feed(data[i:i + 37])
        decoder.finish()
        assert {k: decoder.stats[k] for k in FIGURES} == {k: link[k] for k in FIGURES}, forced


def test_an_hw5_decoders_link_figures_are_the_summarys(hw5_stream, tmp_path):
    path = tmp_path / "hw5.bin"
    path.write_bytes(hw5_stream)
    link = hwfoc.summary(path)["escs"][0]["link"]
    decoder = hwfoc.Decoder(protocol="hw5")
    decoder.feed(hw5_stream)
    decoder.finish()
    got = {k: decoder.stats[k] for k in FIGURES}
    assert got == {k: link[k] for k in FIGURES}
    # No packet counter: its packet figures are not counted (None, not 0).
    assert [got[k] for k in ("lost_packets", "duplicate_packets", "restarts", "delivery_ratio")] == [None] * 4
    assert (got["checksum_failures"], got["rejected_candidates"]) == (1, None)
