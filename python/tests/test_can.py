"""CAN inputs in the Python package: hwfoc.read of a candump log (testdata/dronecan/can-bus.log,
pydronecan's bus) and of a CAN pcapng (testdata/dronecan/pydronecan-frames.pcapng) gives the
records `hwfoc decode` makes, with the schema's Arrow types for the CAN columns (protocol,
node, the ages), and hwfoc.summary the CAN link figures `hwfoc summary --json` gives."""

import json
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
    assert schema.metadata[b"record_schema_version"] == b"3"
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
    assert by_esc[4]["link"]["can"]["crc_errors"] == 1
    assert by_esc[0]["link"]["can"]["unknown_types"] == 1
