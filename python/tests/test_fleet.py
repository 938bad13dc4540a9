"""Fleet scale: 50 simulated recordings on a local Dask cluster (2 workers) and a local Spark
session (local[2]); per-ESC aggregates equal the single-process results exactly, and the
fault episodes are the summary's."""

import json
import os
import sys
import time

import pandas as pd
import pyarrow as pa
import pyarrow.compute
import pytest

import hwfoc
import hwfoc.dask
from conftest import FLEET_NOW, WEEK, cli_records, run_cli

TIMES = {}


def single_process(paths):
    """The reference: each recording read whole, aggregated with pandas, in one process."""
    rows = []
    for path in paths:
        df = hwfoc.read(path).to_pandas()
        for esc, g in df.groupby("esc", sort=True):
            status = g["status"].to_numpy()
            starts = (status != 0) & ~pd.Series(status != 0).shift(1, fill_value=False).to_numpy()
            rows.append({
                "recording": path,
                "esc": int(esc),
                "rows": len(g),
                "max_mos_temp_c": float(g["mos_temp_c"].max()),
                "min_voltage_v": float(g["voltage_v"].min()),
                "fault_episodes": int(starts.sum()),
            })
    return pd.DataFrame(rows).sort_values(["recording", "esc"]).reset_index(drop=True)


@pytest.fixture(scope="module")
def reference(fleet):
    t = time.perf_counter()
    ref = single_process(fleet)
    TIMES["single process"] = time.perf_counter() - t
    return ref


def normalise(df):
    df = df[["recording", "esc", "rows", "max_mos_temp_c", "min_voltage_v", "fault_episodes"]].copy()
    df["recording"] = df["recording"].astype(str)
    for c in ("esc", "rows", "fault_episodes"):
        df[c] = df[c].astype("int64")
    for c in ("max_mos_temp_c", "min_voltage_v"):
        df[c] = df[c].astype("float64")
    return df.sort_values(["recording", "esc"]).reset_index(drop=True)


def test_the_fleet_has_faults_and_several_escs(fleet, reference):
    assert len(fleet) == 50
    assert reference["esc"].max() == 3
    assert (reference["fault_episodes"] > 0).sum() >= 10
    assert reference["fault_episodes"].max() >= 2


def test_episodes_are_the_summarys(fleet, reference):
    for path in fleet[::7]:
        summary = hwfoc.summary(path)
        got = reference[reference["recording"] == path]
        for esc in summary["escs"]:
            row = got[got["esc"] == esc["esc"]].iloc[0]
            assert row["fault_episodes"] == esc["fault_episode_count"]
            assert row["rows"] == esc["frames"]


def test_dask_on_a_local_cluster(fleet, reference):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster):
        t = time.perf_counter()
        ddf = hwfoc.dask.read(os.path.join(os.path.dirname(fleet[0]), "rec-*.pcapng"), path_column="recording")
        assert ddf.npartitions == 50
        meta = ddf._meta
        schema = hwfoc.record_schema()
        assert list(meta.columns) == schema.names + ["recording"]
        assert str(meta["esc"].dtype) == "uint8" and str(meta["erpm"].dtype) == "uint32"
        assert str(meta["mos_temp_c"].dtype) == "float32" and str(meta["t_s"].dtype) == "float64"
        got = hwfoc.dask.esc_aggregates(ddf).compute()
        TIMES["dask"] = time.perf_counter() - t
        pd.testing.assert_frame_equal(normalise(got), normalise(reference))
        # A filter and a reduction across the fleet: which ESCs ran hot in the last week.
        last_week = ddf[ddf["t_s"] >= FLEET_NOW - WEEK]
        hot = last_week.groupby(["recording", "esc"])["mos_temp_c"].max().compute()
        ref = []
        for path in fleet:
            df = hwfoc.read(path, start=FLEET_NOW - WEEK).to_pandas()
            for esc, g in df.groupby("esc"):
                ref.append(((path, esc), g["mos_temp_c"].max()))
        assert dict(hot.items()) == dict(ref)
        assert 0 < len(ref) < len(reference)


def test_dask_read_errors(tmp_path):
    with pytest.raises(hwfoc.InputError, match="no file matches"):
        hwfoc.dask.read(str(tmp_path / "*.pcapng"))
    ddf = hwfoc.dask.read(str(tmp_path / "missing.pcapng"))
    with pytest.raises(hwfoc.InputError, match="cannot open"):
        ddf.compute(scheduler="sync")


@pytest.fixture(scope="module")
def spark():
    os.environ.setdefault("PYSPARK_PYTHON", sys.executable)
    os.environ.setdefault("PYSPARK_DRIVER_PYTHON", sys.executable)
    from pyspark.sql import SparkSession

    session = (
        SparkSession.builder.master("local[2]")
        .appName("hwfoc-tests")
        .config("spark.ui.enabled", "false")
        .config("spark.sql.shuffle.partitions", "4")
        .config("spark.sql.execution.arrow.pyspark.enabled", "true")
        .getOrCreate()
    )
    yield session
    session.stop()


def test_spark_local(spark, fleet, reference):
    import hwfoc.spark

    t = time.perf_counter()
    df = hwfoc.spark.read(spark, fleet, path_column="recording", frame_column="frame")
    schema = df.schema
    assert schema.names == hwfoc.record_schema().names + ["frame", "recording"]
    assert schema["voltage_v"].metadata == {"unit": "V"}
    got = hwfoc.spark.esc_aggregates(df).toPandas()
    TIMES["spark"] = time.perf_counter() - t
    pd.testing.assert_frame_equal(normalise(got), normalise(reference))
    assert df.count() == reference["rows"].sum()
    row = df.filter("status != 0").select("faults").first()
    assert row is not None and len(row["faults"]) >= 1


def test_dask_and_spark_name_recordings_alike(spark, fleet, monkeypatch):
    # Relative paths, as a user in the fleet's folder gives them: both readers name each
    # recording as given (Spark's workers still read it by its absolute path).
    import hwfoc.spark

    folder = os.path.dirname(fleet[0])
    monkeypatch.chdir(folder)
    given = [os.path.basename(p) for p in fleet[:2]]
    from_dask = set(hwfoc.dask.read(given, path_column="recording")["recording"].unique().compute())
    spark_rows = hwfoc.spark.read(spark, given, path_column="recording").select("recording").distinct().collect()
    from_spark = {r["recording"] for r in spark_rows}
    assert from_dask == from_spark == set(given)


def test_report_times():
    # Printed for the record (pytest -s); the figures are in the README's notes.
    for k, v in TIMES.items():
        print(f"fleet of 50: {k}: {v:.2f} s")
    assert "single process" in TIMES


def test_drones_recorded_together_give_each_recordings_rows_everywhere(cli, tmp_path, spark):
    """Three drones recorded at the same time on ports named alike (esc-0, esc-1): the command,
    hwfoc.read, Dask and Spark give each recording's rows as the recording read alone, and the
    escs metadata names each ESC's input."""
    import hwfoc.spark

    paths = []
    for i in (1, 2, 3):
        path = tmp_path / f"drone-{i}.pcapng"
        run_cli(cli, "simulate", "--escs", 2, "--duration", 10, "--seed", i, "-o", path)
        paths.append(str(path))
    alone = {p: hwfoc.read(p) for p in paths}
    rows = {p: t.num_rows for p, t in alone.items()}
    # The command: every recording's records, ESCs numbered in the order given.
    together = cli_records(cli, *paths)
    assert len(together) == sum(rows.values())
    table = hwfoc.read(paths)
    assert table.num_rows == len(together)
    assert table.column("esc").to_pylist() == [r["esc"] for r in together]
    escs = json.loads(table.schema.metadata[b"escs"])
    assert [(e["esc"], e["input"]) for e in escs] == [
        (2 * k + e, p) for k, p in enumerate(paths) for e in (0, 1)
    ]
    for k, p in enumerate(paths):
        for e in (0, 1):
            mine = table.filter(pa.compute.equal(table.column("esc"), 2 * k + e))
            theirs = alone[p].filter(pa.compute.equal(alone[p].column("esc"), e))
            for column in ("t_s", "packet", "rpm", "voltage_v"):
                assert mine.column(column).to_pylist() == theirs.column(column).to_pylist(), (p, e)
    ddf = hwfoc.dask.read(paths, path_column="recording").compute(scheduler="sync")
    assert ddf.groupby("recording").size().to_dict() == rows
    df = hwfoc.spark.read(spark, paths, path_column="recording")
    assert {r["recording"]: r["count"] for r in df.groupBy("recording").count().collect()} == rows
