#!/usr/bin/env python3
"""Checks that query engines skip row groups of `hwfoc decode --format parquet` by statistics.

Usage: parquet_stats_check.py HWFOC [WORKDIR]

HWFOC is the path of the hwfoc binary. The script simulates a recording whose values change
over time (16 virtual ESCs for 70 minutes, the throttle climbing from idle to full, so the
MOSFETs warm up row group after row group; two fault episodes; pcapng, so `t_s` is Unix
time), exports it as
Parquet (10 row groups or more), then:

- pyarrow: every column chunk of every row group has statistics: a null count, and a minimum
  and maximum equal to those of the values (computed from the data read back); the list column
  `faults` has its null count (and min/max names only in row groups with faults);
- DuckDB: `parquet_metadata(...)` shows the same minimum, maximum and null count for every
  column chunk;
- for filters on `mos_temp_c` (a threshold in the middle of the row groups' maxima) and on
  `t_s` (a 5-minute window), the row groups the statistics allow are counted from the metadata
  (fewer than all, and at least one), and each engine must read exactly that many:
  DuckDB's `EXPLAIN ANALYZE` ("Row Groups Scanned: N / M"), polars' verbose log
  ("Predicate pushdown: reading N / M row groups"), pyarrow's dataset fragments split by row
  group with the filter; each engine's filtered count equals the count over all rows.

Needs pyarrow, duckdb and polars. Exits non-zero with a message on the first difference; prints
"1 passed, 0 failed" when all is well.
"""

import datetime
import math
import os
import re
import struct
import subprocess
import sys
import tempfile

import duckdb
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.dataset as ds
import pyarrow.parquet as pq

ESCS = 16
DURATION_S = 4200
START = 1_700_000_000


FLOAT32 = {"throttle_in_pct", "throttle_out_pct", "rpm", "voltage_v", "current_a",
           "phase_current_a", "mos_temp_c", "cap_temp_c", "motor_temp_c", "bec_temp_c",
           "bec_voltage_v", "bec_current_a"}

# Leaf columns of record schema 4 (faults: its one leaf).
COLUMNS = 23

# Columns the decoded file (HW-FOC ESCs) does not carry (record schemas 2 and 3): null in every
# row, so a row group has a null count and no minimum or maximum.
NOT_CARRIED = {"motor_temp_c", "bec_temp_c", "bec_voltage_v", "bec_current_a", "node", "msg2_age_ms",
               "msg3_age_ms"}


def f32(x):
    """The float32 nearest to `x`."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def check(cond, message):
    if not cond:
        sys.exit(f"parquet_stats_check: {message}")


def run(*args, env=None):
    out = subprocess.run(args, capture_output=True, text=True, env=env)
    check(out.returncode == 0, f"{' '.join(args)} failed: {out.stderr}")
    return out


def export(hwfoc, work):
    """The simulated recording, as Parquet: its path."""
    profile = os.path.join(work, "climb.csv")
    with open(profile, "w") as f:
        f.write("time_s,throttle_percent\n0,0\n60,5\n%d,100\n" % DURATION_S)
    recording = os.path.join(work, "climb.pcapng")
    run(hwfoc, "simulate", "--escs", str(ESCS), "--duration", str(DURATION_S), "--seed", "7",
        "--profile", f"csv:{profile}", "--start-time", str(START), "--quiet", "-o", recording,
        # Fault names in some row groups only: the list column's statistics then vary too.
        "--fault", "3:mos_overheat@600-660", "--fault", "5:throttle_signal_lost@1800-1830")
    parquet = os.path.join(work, "climb.parquet")
    run(hwfoc, "decode", "--format", "parquet", "-o", parquet, recording)
    return parquet


def same(a, b):
    """Two statistics values equal (floats as the float32 or float64 they are)."""
    if isinstance(a, float) or isinstance(b, float):
        return a is not None and b is not None and math.isclose(a, b, rel_tol=0, abs_tol=0)
    return a == b


def check_pyarrow_statistics(path):
    """Every column chunk's statistics are the values' own. Returns them per row group:
    {column: (min, max, null_count)}."""
    f = pq.ParquetFile(path)
    meta = f.metadata
    check(meta.num_row_groups >= 8, f"{meta.num_row_groups} row groups: expected 8 or more")
    groups = []
    for r in range(meta.num_row_groups):
        table = f.read_row_group(r)
        rg = meta.row_group(r)
        stats = {}
        for i in range(rg.num_columns):
            chunk = rg.column(i)
            name = chunk.path_in_schema
            s = chunk.statistics
            check(chunk.is_stats_set and s is not None, f"row group {r} {name}: no statistics")
            check(s.has_null_count, f"row group {r} {name}: no null count")
            if name == "faults.list.item":
                names = pc.list_flatten(table.column("faults"))
                empty = sum(1 for v in table.column("faults").to_pylist() if not v)
                check(s.null_count == empty,
                      f"row group {r} faults: null count {s.null_count}, {empty} empty lists")
                if len(names) == 0:
                    check(not s.has_min_max, f"row group {r} faults: min/max of no names")
                else:
                    mm = pc.min_max(names).as_py()
                    check(s.has_min_max and (s.min, s.max) == (mm["min"], mm["max"]),
                          f"row group {r} faults: {s.min}..{s.max}, names {mm}")
                stats[name] = (s.min if s.has_min_max else None,
                               s.max if s.has_min_max else None, s.null_count)
                continue
            column = table.column(name)
            if name in NOT_CARRIED:
                check(column.null_count == table.num_rows and s.null_count == table.num_rows,
                      f"row group {r} {name}: null count {s.null_count} of {table.num_rows}")
                check(not s.has_min_max, f"row group {r} {name}: min/max of nulls")
                stats[name] = (None, None, s.null_count)
                continue
            if pa.types.is_dictionary(column.type):
                # `protocol`: its statistics are those of the names.
                column = column.cast(pa.string())
            mm = pc.min_max(column).as_py()
            check(s.null_count == column.null_count,
                  f"row group {r} {name}: null count {s.null_count}, {column.null_count} nulls")
            check(s.has_min_max, f"row group {r} {name}: no minimum and maximum")
            check(same(s.min, mm["min"]) and same(s.max, mm["max"]),
                  f"row group {r} {name}: statistics {s.min}..{s.max}, values "
                  f"{mm['min']}..{mm['max']}")
            stats[name] = (s.min, s.max, s.null_count)
        groups.append(stats)
    return groups


def check_duckdb_metadata(path, groups):
    """DuckDB reads the same statistics."""
    rows = duckdb.sql(
        "SELECT row_group_id, path_in_schema, stats_min_value, stats_max_value, "
        f"stats_null_count FROM parquet_metadata('{path}')").fetchall()
    check(len(rows) == len(groups) * COLUMNS, f"DuckDB sees {len(rows)} column chunks")
    for rg, column, lo, hi, nulls in rows:
        name = column.replace(", ", ".")
        want_lo, want_hi, want_nulls = groups[rg][name]
        check(nulls == want_nulls, f"DuckDB: row group {rg} {name}: null count {nulls}")
        if want_lo is None:
            check(lo is None and hi is None, f"DuckDB: row group {rg} {name}: {lo}..{hi}")
            continue
        check(lo is not None and hi is not None,
              f"DuckDB: row group {rg} {name}: no minimum and maximum")
        if isinstance(want_lo, str):
            check((lo, hi) == (want_lo, want_hi), f"DuckDB: row group {rg} {name}: {lo}..{hi}")
        elif isinstance(want_lo, datetime.datetime):
            # `time`: DuckDB writes the instants as text, `2023-11-14 22:13:20.005807+00`.
            lo, hi = datetime.datetime.fromisoformat(lo), datetime.datetime.fromisoformat(hi)
            check((lo, hi) == (want_lo, want_hi),
                  f"DuckDB: row group {rg} {name}: {lo}..{hi}, pyarrow {want_lo}..{want_hi}")
        else:
            # DuckDB prints a float32 as its shortest text: compare as float32 there.
            as_type = f32 if name in FLOAT32 else float
            lo, hi = as_type(float(lo)), as_type(float(hi))
            check(same(lo, as_type(want_lo)) and same(hi, as_type(want_hi)),
                  f"DuckDB: row group {rg} {name}: {lo}..{hi}, pyarrow {want_lo}..{want_hi}")


def duckdb_scan(path, where):
    """The matching rows' count and the row groups DuckDB scanned, of how many."""
    count = duckdb.sql(f"SELECT count(*) FROM '{path}' WHERE {where}").fetchall()[0][0]
    plan = duckdb.sql(f"EXPLAIN ANALYZE SELECT count(*), max(rpm) FROM '{path}' WHERE {where}")
    text = plan.fetchall()[0][1]
    m = re.search(r"Row Groups Scanned: (\d+) / (\d+)", text)
    check(m, f"DuckDB's EXPLAIN ANALYZE does not count row groups:\n{text}")
    return count, int(m.group(1)), int(m.group(2))


POLARS = """
import sys, polars as pl
path, column, lo, hi = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
n = pl.scan_parquet(path).filter(pl.col(column).is_between(lo, hi)).select(pl.len()).collect()
print(n.item())
"""


def polars_scan(path, column, lo, hi):
    """The matching rows' count and the row groups polars read, of how many (from its verbose
    log, in a process of its own)."""
    env = dict(os.environ, POLARS_VERBOSE="1")
    out = run(sys.executable, "-c", POLARS, path, column, repr(lo), repr(hi), env=env)
    m = re.search(r"Predicate pushdown: reading (\d+) / (\d+) row groups", out.stderr)
    if m is None:
        # Nothing pruned: polars says only how many row groups it read.
        m = re.search(r"Deferred cached reads: (\d+) / (\d+) row groups", out.stderr)
    check(m, f"polars' log does not count row groups:\n{out.stderr[-3000:]}")
    return int(out.stdout.strip()), int(m.group(1)), int(m.group(2))


def pyarrow_scan(path, column, lo, hi):
    """The matching rows' count and the row groups pyarrow keeps for the filter, of how many."""
    fragment = next(ds.dataset(path, format="parquet").get_fragments())
    condition = (ds.field(column) >= lo) & (ds.field(column) <= hi)
    kept = fragment.split_by_row_group(condition)
    count = sum(f.to_table(filter=condition).num_rows for f in kept)
    return count, len(kept), fragment.metadata.num_row_groups


def check_pruning(path, groups, column, lo, hi):
    """A filter `lo <= column <= hi`: each engine reads exactly the row groups whose
    statistics overlap it, fewer than all, and counts the same rows as a full scan."""
    overlap = sum(1 for g in groups if g[column][0] <= hi and g[column][1] >= lo)
    total = len(groups)
    check(0 < overlap < total,
          f"{column} in [{lo}, {hi}]: {overlap} of {total} row groups overlap: the test data "
          "does not vary enough over time")
    table = pq.read_table(path, columns=[column])
    values = table.column(column)
    expected = pc.sum(pc.and_(pc.greater_equal(values, lo), pc.less_equal(values, hi))).as_py()
    where = f"{column} BETWEEN {lo!r} AND {hi!r}"
    for engine, (count, read, of) in [
        ("DuckDB", duckdb_scan(path, where)),
        ("polars", polars_scan(path, column, lo, hi)),
        ("pyarrow", pyarrow_scan(path, column, lo, hi)),
    ]:
        check(of == total, f"{engine}: {of} row groups, the file has {total}")
        check(read == overlap,
              f"{engine} read {read} of {total} row groups for {where}; the statistics "
              f"allow {overlap}")
        check(count == expected, f"{engine}: {count} rows for {where}, expected {expected}")
        print(f"{engine:8} {where}: {read} of {total} row groups read, {count} rows")


def check_time(path):
    """DuckDB, polars and pyarrow read `time` as a UTC timestamp with no conversion, holding
    the instant of `t_s` in every row."""
    start = datetime.datetime.fromtimestamp(START, datetime.timezone.utc)
    kind = duckdb.sql(f"SELECT typeof(time) FROM '{path}' LIMIT 1").fetchall()[0][0]
    check(kind == "TIMESTAMP WITH TIME ZONE", f"DuckDB reads time as {kind}")
    rows, differ, first = duckdb.sql(
        "SELECT count(*), count(*) FILTER (WHERE epoch_us(time) != round(t_s * 1e6)), "
        f"epoch_us(min(time)) FROM '{path}'").fetchall()[0]
    check(rows > 0 and differ == 0, f"DuckDB: {differ} of {rows} rows' time is not t_s")
    check(first // 1_000_000 == START, f"DuckDB: the first time is {first} us")
    out = run(sys.executable, "-c", POLARS_TIME, path).stdout.split()
    check(out[0] == "Datetime(time_unit='us',time_zone='UTC')", f"polars reads time as {out[0]}")
    check(out[1] == "0", f"polars: {out[1]} rows' time is not t_s")
    column = pq.read_table(path, columns=["time"]).column("time")
    check(column.type == pa.timestamp("us", tz="UTC"), f"pyarrow reads time as {column.type}")
    check(column[0].as_py().replace(microsecond=0) == start, f"pyarrow: first time {column[0]}")
    print(f"time: a UTC timestamp in DuckDB, polars and pyarrow, {rows} rows equal to t_s")


POLARS_TIME = """
import sys, polars as pl
df = pl.read_parquet(sys.argv[1], columns=["t_s", "time"])
us = (df["t_s"] * 1e6).round(mode="half_away_from_zero").cast(pl.Int64)
print(str(df.schema["time"]).replace(" ", ""), (df["time"].dt.epoch("us") != us).sum())
"""


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__.split("\n\n")[1])
    hwfoc = sys.argv[1]
    if len(sys.argv) == 3:
        os.makedirs(sys.argv[2], exist_ok=True)
        checks(hwfoc, sys.argv[2])
    else:
        # Removed afterwards, whether the checks pass or not.
        with tempfile.TemporaryDirectory(prefix="hwfoc-stats-") as work:
            checks(hwfoc, work)


def checks(hwfoc, work):
    """The checks, with their files in `work`."""
    path = export(hwfoc, work)
    groups = check_pyarrow_statistics(path)
    with_names = sum(1 for g in groups if g["faults.list.item"][0] is not None)
    check(0 < with_names < len(groups), f"{with_names} row groups with fault names")
    check_duckdb_metadata(path, groups)
    # Hot MOSFETs: above the middle of the row groups' maxima (a float32 column).
    maxima = sorted(g["mos_temp_c"][1] for g in groups)
    hot = maxima[len(maxima) // 2] + 0.5
    check_pruning(path, groups, "mos_temp_c", hot, 1000.0)
    # Five minutes, twenty minutes in.
    t0 = START + 1200.0
    check_pruning(path, groups, "t_s", t0, t0 + 300.0)
    check_time(path)
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
