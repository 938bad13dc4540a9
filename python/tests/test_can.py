"""CAN inputs in the Python package: hwfoc.read of a candump log (testdata/dronecan/can-bus.log,
pydronecan's bus) and of a CAN pcapng (testdata/dronecan/pydronecan-frames.pcapng) gives the
records `hwfoc decode` makes, with the schema's Arrow types for the CAN columns (protocol,
node, the ages), and hwfoc.summary the CAN link figures `hwfoc summary --json` gives."""

import json
import re
import subprocess
import warnings
from pathlib import Path

import pyarrow as pa
import pytest

import hwfoc
from conftest import assert_same_records, cli_records, run_cli

DRONECAN = Path(__file__).resolve().parents[2] / "testdata" / "dronecan"
LOG = DRONECAN / "can-bus.log"
PCAPNG = DRONECAN / "pydronecan-frames.pcapng"


# Pydronecan's capture puts a Hobbywing node without a GetEscID answer (numbered by its node id, 3)
# beside a standard ESC of esc_index 3: both claim place 3, two ESCs, told once. No other warning:
# the capture's bus has no ESC at place 0, which is no wire without frames.
WARNINGS = {LOG.name: [], PCAPNG.name: ["node 3 (no GetEscID answer: by its node id) and node 20 (esc_index 3) both claim place 3"]}


@pytest.mark.parametrize("path", [LOG, PCAPNG], ids=lambda p: p.name)
def test_can_inputs_read_as_decode(cli, path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", hwfoc.HwfocWarning)
        table = hwfoc.read(str(path))
    told = [str(w.message) for w in caught if issubclass(w.category, hwfoc.HwfocWarning)]
    expected = WARNINGS[path.name]
    assert len(told) == len(expected) and all(e in t for e, t in zip(expected, told)), told
    assert table.num_rows > 0
    assert_same_records(table, cli_records(cli, path))


def test_can_columns_have_the_schema_types():
    table = hwfoc.read(str(LOG))
    schema = table.schema
    assert schema.metadata[b"record_schema_version"] == b"4"
    assert schema.field("protocol").type == pa.dictionary(pa.int8(), pa.string())
    assert schema.field("esc").type == pa.uint8()
    assert schema.field("node").type == pa.uint8() and schema.field("node").nullable
    for age in ("msg2_age_ms", "msg3_age_ms"):
        assert schema.field(age).type == pa.uint32() and schema.field(age).nullable
        assert schema.field(age).metadata[b"unit"] == b"ms"
    assert schema.field("packet").type == pa.uint32()
    assert schema.equals(hwfoc.record_schema(), check_metadata=False)


def test_can_records_carry_protocol_node_and_ages():
    rows = hwfoc.read(str(LOG)).to_pylist()
    assert len(rows) == 58
    assert {r["protocol"] for r in rows} == {"hw-can", "dronecan"}
    # ESCs by place on the bus, the file read ahead: nodes 11 and 12 by the throttle channel - 1
    # their GetEscID answers give, every record; node 13 never answered (its node id);
    # standard ESCs by esc_index.
    pairs = sorted({(r["esc"], r["node"]) for r in rows})
    assert pairs == [(0, 11), (1, 12), (3, 40), (4, 41), (13, 13)]
    hw = [r for r in rows if r["protocol"] == "hw-can"]
    std = [r for r in rows if r["protocol"] == "dronecan"]
    assert all(r["packet"] is None and r["throttle_in_pct"] is None and r["faults"] is None for r in hw)
    assert any(r["msg2_age_ms"] is None for r in hw) and any(r["msg3_age_ms"] is not None for r in hw)
    assert all(r["msg3_age_ms"] is None and r["status"] is None and r["cap_temp_c"] is None for r in std)
    assert any(r["msg2_age_ms"] is not None for r in std)
    # Node 12 turns counter-clockwise: status bit 14 on each of its records.
    assert all(r["status"] & 0x4000 for r in hw if r["node"] == 12)
    # A NaN voltage is null.
    assert any(r["voltage_v"] is None for r in std)


def test_can_records_can_be_selected_by_esc():
    table = hwfoc.read(str(LOG), esc=[0, 3])
    assert set(table.column("esc").to_pylist()) == {0, 3}
    assert set(table.column("node").to_pylist()) == {11, 40}


def test_summary_of_a_can_bus_is_the_commands(cli):
    got = hwfoc.summary(str(LOG))
    out, _, _ = run_cli(cli, "summary", "--json", LOG)
    want = json.loads(out)
    assert [e["esc"] for e in got["escs"]] == [e["esc"] for e in want["escs"]]
    for g, w in zip(got["escs"], want["escs"]):
        assert g["protocol"] == w["protocol"]
        assert g["link"]["can"] == w["link"]["can"]
    by_esc = {e["esc"]: e for e in got["escs"]}
    assert by_esc[0]["link"]["can"]["node"] == 11
    assert by_esc[4]["link"]["checksum_failures"] == 1
    assert "crc_errors" not in by_esc[4]["link"]["can"]
    assert by_esc[0]["link"]["can"]["unknown_types"] == 1


# hwfoc.CanDecoder: frames a caller holds, as tuples or python-can Messages. Its ESCs are
# numbered as a live bus's are (as `hwfoc decode -` reads the log, not ahead); every other
# column is what hwfoc.read gives of the candump log of the same frames.


def _log_tuples():
    """The candump log's frames as (timestamp, arbitration_id, data, is_extended) tuples."""
    frames = []
    for line in LOG.read_text().splitlines():
        stamp, _, frame = line.split()
        ident, data = frame.split("#")
        frames.append((float(stamp.strip("()")), int(ident, 16), bytes.fromhex(data), len(ident) == 8))
    return frames


def _decoded(batches):
    return pa.Table.from_batches([b for b in batches if b.num_rows], schema=batches[0].schema)


def _by_time(table):
    """The records in time order (stable). A live decoder gives a Hobbywing node's records held
    before its GetEscID answer when the answer (or `finish`) places them, after later records of
    other nodes; the command and `hwfoc.read` give every record in time order."""
    return table.sort_by([("t_s", "ascending")])


def _live_records(cli):
    """`hwfoc decode -` of the candump log: its ESCs numbered as heard."""
    with open(LOG, "rb") as f:
        out = subprocess.run([cli, "decode", "-"], stdin=f, capture_output=True, check=True).stdout
    return [json.loads(line) for line in out.splitlines()]


def _without_esc(rows):
    return [{k: v for k, v in r.items() if k != "esc"} for r in rows]


def test_can_decoder_gives_the_records_of_the_log_from_tuples(cli):
    frames = _log_tuples()
    assert len(frames) == 135
    whole = hwfoc.CanDecoder()
    table = _decoded([whole.feed(frames), whole.finish()])
    assert_same_records(_by_time(table), _live_records(cli))
    assert _without_esc(_by_time(table).to_pylist()) == _without_esc(hwfoc.read(str(LOG)).to_pylist())
    assert whole.stats["bytes"] == 135 * 16
    # Fed one frame at a time, or in uneven pieces: the same records.
    one = hwfoc.CanDecoder()
    assert _decoded([one.feed(f) for f in frames] + [one.finish()]).equals(table)
    pieces = hwfoc.CanDecoder()
    assert _decoded(
        [pieces.feed(frames[i : i + 7]) for i in range(0, len(frames), 7)] + [pieces.finish()]
    ).equals(table)
    # `esc` offsets the ESC numbers.
    shifted_decoder = hwfoc.CanDecoder(esc=20)
    shifted = _decoded([shifted_decoder.feed(frames), shifted_decoder.finish()])
    assert shifted.column("esc").to_pylist() == [e + 20 for e in table.column("esc").to_pylist()]


def test_can_decoder_takes_python_can_messages(cli):
    can = pytest.importorskip("can", reason="python-can is not installed (.ci/python.sh installs it)")
    messages = list(can.LogReader(str(LOG)))
    decoder = hwfoc.CanDecoder()
    table = _decoded([decoder.feed(messages), decoder.finish()])
    assert_same_records(_by_time(table), _live_records(cli))
    assert _without_esc(_by_time(table).to_pylist()) == _without_esc(hwfoc.read(str(LOG)).to_pylist())
    # The files python-can writes of those frames, read back by python-can, give them again
    # (not its TRC: its reader adds float offsets to a float start, so its times move by ulps).
    for name in ["can-bus.blf", "can-bus.csv"]:
        reread = hwfoc.CanDecoder()
        again = _decoded([reread.feed(can.LogReader(str(DRONECAN / name))), reread.finish()])
        assert again.equals(table), name


def test_can_decoder_refuses_what_is_no_classic_can_frame():
    decoder = hwfoc.CanDecoder()
    bad = [
        ((1.0, 0x800, b"", False), "arbitration_id 0x800 with 0 data bytes is no classic CAN frame"),
        ((1.0, 0x123, bytes(9), False), "with 9 data bytes is no classic CAN frame"),
        ((1.0, 0x2000_0000, b"", True), "is no classic CAN frame (29-bit id"),
        ((2e10, 0x123, b"", False), "timestamp: 20000000000 is not a time in seconds from 1970"),
        ((float("nan"), 0x123, b"", False), "timestamp: NaN is not a time"),
        ((-1.0, 0x123, b"", False), "timestamp: -1 is not a time"),
        ((1.0, 0x123, b""), "a frame tuple is (timestamp, arbitration_id, data, is_extended)"),
    ]
    for frame, message in bad:
        with pytest.raises(ValueError, match=re.escape(message)):
            decoder.feed([frame])
    with pytest.raises(TypeError):
        decoder.feed([(1.0, 0x123, "text", False)])
    assert decoder.feed([]).num_rows == 0
