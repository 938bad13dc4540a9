#!/usr/bin/env python3
"""Checks `hwfoc decode --format parquet` with pyarrow, as a data scientist would read the file.

Usage: pyarrow_check.py HWFOC [WORKDIR]

HWFOC is the path of the hwfoc binary. The script exports the built-in demo capture twice, as
Parquet and as JSON Lines, under non-default settings, then asserts with pyarrow: the column names,
types and nullability of docs/RECORD-SCHEMA.md, the unit of each column in the field metadata, the
settings, version, inputs and ESCs in the file's key-value metadata and in the table's schema
metadata (what `read_table(f).schema.metadata` shows), and every value equal to the
JSON Lines record of the same row. Needs pyarrow only (no numpy, no pandas). Exits non-zero with a
message on the first difference; prints "1 passed, 0 failed" when all is well.
"""

import datetime
import json
import math
import os
import struct
import subprocess
import sys
import tempfile

import pyarrow as pa
import pyarrow.parquet as pq

SCHEMA = [
    ("t_s", pa.float64(), True, "s"),
    ("esc", pa.uint8(), False, "-"),
    ("protocol", pa.dictionary(pa.int8(), pa.string()), False, "-"),
    ("packet", pa.uint32(), True, "-"),
    ("throttle_in_pct", pa.float32(), True, "%"),
    ("throttle_out_pct", pa.float32(), True, "%"),
    ("erpm", pa.uint32(), True, "rev/min"),
    ("rpm", pa.float32(), True, "rev/min"),
    ("voltage_v", pa.float32(), True, "V"),
    ("current_a", pa.float32(), True, "A"),
    ("phase_current_a", pa.float32(), True, "A"),
    ("mos_temp_c", pa.float32(), True, "degC"),
    ("cap_temp_c", pa.float32(), True, "degC"),
    ("motor_temp_c", pa.float32(), True, "degC"),
    ("bec_temp_c", pa.float32(), True, "degC"),
    ("bec_voltage_v", pa.float32(), True, "V"),
    ("bec_current_a", pa.float32(), True, "A"),
    ("status", pa.uint16(), True, "-"),
    ("faults", pa.list_(pa.field("item", pa.string(), nullable=False)), True, "-"),
    ("node", pa.uint8(), True, "-"),
    ("msg2_age_ms", pa.uint32(), True, "ms"),
    ("msg3_age_ms", pa.uint32(), True, "ms"),
    ("time", pa.timestamp("us", tz="UTC"), True, "-"),
]

# Columns of Parquet and Arrow only (record schema 4): not in JSON Lines.
BINARY_ONLY = ["time"]

EPOCH = datetime.datetime(1970, 1, 1, tzinfo=datetime.timezone.utc)


def instant(t_s):
    """The UTC instant of `t_s` to the microsecond, as the `time` column holds it (halves
    rounded away from zero, as Rust's `f64::round`; Python's `round` takes the even one)."""
    if t_s is None:
        return None
    us = t_s * 1e6
    return EPOCH + datetime.timedelta(microseconds=math.copysign(math.floor(abs(us) + 0.5), us))

# Columns of record schemas 2 and 3 that HW-FOC (the demo capture) does not carry: null in every
# row.
NOT_CARRIED = ["motor_temp_c", "bec_temp_c", "bec_voltage_v", "bec_current_a", "node", "msg2_age_ms",
               "msg3_age_ms"]

SETTINGS = {"current_scale": "100", "pole_pairs": "14", "gear_ratio": "2.5"}


def f32(x):
    """The float32 nearest to a JSON number (the JSON text is the shortest text of a float32)."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def check(cond, message):
    if not cond:
        sys.exit(f"pyarrow_check: {message}")


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__.split("\n\n")[1])
    hwfoc = sys.argv[1]
    if len(sys.argv) == 3:
        os.makedirs(sys.argv[2], exist_ok=True)
        checks(hwfoc, sys.argv[2])
    else:
        # Removed afterwards, whether the checks pass or not.
        with tempfile.TemporaryDirectory(prefix="hwfoc-pyarrow-") as work:
            checks(hwfoc, work)


def checks(hwfoc, work):
    """The checks, with their files in `work`."""
    parquet_path = os.path.join(work, "demo.parquet")
    settings = [arg for k, v in SETTINGS.items() for arg in (f"--{k.replace('_', '-')}", v)]
    base = [hwfoc, "decode", "--demo", *settings]
    subprocess.run([*base, "--format", "parquet", "-o", parquet_path], check=True)
    lines = subprocess.run(base, check=True, capture_output=True, text=True).stdout.splitlines()
    records = [json.loads(line) for line in lines]
    check(len(records) > 100, f"only {len(records)} JSON records")

    schema = pq.read_schema(parquet_path)
    check(schema.names == [name for name, *_ in SCHEMA], f"column names {schema.names}")
    for field, (name, typ, nullable, unit) in zip(schema, SCHEMA):
        check(field.type == typ, f"{name}: type {field.type}, expected {typ}")
        check(field.nullable == nullable, f"{name}: nullable {field.nullable}")
        meta = field.metadata or {}
        check(meta.get(b"unit") == unit.encode(), f"{name}: unit {meta.get(b'unit')!r}, expected {unit!r}")

    kv = pq.ParquetFile(parquet_path).metadata.metadata
    for key, value in SETTINGS.items():
        check(kv.get(key.encode()) == value.encode(), f"metadata {key}: {kv.get(key.encode())!r}")
    check(kv.get(b"hwfoc_version", b"") != b"", "no hwfoc_version in the metadata")
    check(kv.get(b"record_schema_version") == b"4", f"record_schema_version {kv.get(b'record_schema_version')!r}")
    check(json.loads(kv[b"inputs"]) == ["demo capture"], f"inputs {kv[b'inputs']!r}")
    escs = json.loads(kv[b"escs"])
    check(escs == [{"esc": 0, "input": "demo capture", "stream": "demo capture", "protocol": "hw-foc"}], f"escs {escs}")

    table = pq.read_table(parquet_path)
    check(table.num_rows == len(records), f"{table.num_rows} rows, {len(records)} JSON records")
    # The same metadata where a reader of the table looks for it: the Arrow schema's.
    table_meta = table.schema.metadata or {}
    for key, value in kv.items():
        if key != b"ARROW:schema":
            check(table_meta.get(key) == value, f"read_table's schema metadata {key!r}: {table_meta.get(key)!r}")
    rows = table.to_pylist()
    floats = {name for name, typ, *_ in SCHEMA if typ == pa.float32()}
    for i, (row, record) in enumerate(zip(rows, records)):
        check([k for k in row if k not in BINARY_ONLY] == list(record), f"row {i}: keys {list(row)}")
        check(row["time"] == instant(record["t_s"]), f"row {i} time: {row['time']!r}, t_s {record['t_s']!r}")
        for name, value in record.items():
            got = row[name]
            if name in floats and value is not None:
                value = f32(value)
            check(got == value, f"row {i} {name}: parquet {got!r}, JSON {value!r}")
    # `protocol` is dictionary-encoded in the Parquet file itself (its column chunks), and read
    # back as a dictionary; the demo is one ESC's own wire.
    meta = pq.ParquetFile(parquet_path).metadata
    at = schema.names.index("protocol")
    for g in range(meta.num_row_groups):
        column = meta.row_group(g).column(at)
        check(column.has_dictionary_page, f"protocol: row group {g} has no dictionary page")
        check(column.physical_type == "BYTE_ARRAY", f"protocol: physical type {column.physical_type}")
    protocol = table.column("protocol")
    check(pa.types.is_dictionary(protocol.type), f"protocol read as {protocol.type}")
    check(set(protocol.to_pylist()) == {"hw-foc"}, f"protocol values {set(protocol.to_pylist())}")
    check(pa.types.is_uint32(table.column("packet").type), f"packet read as {table.column('packet').type}")
    check(max(r["packet"] for r in rows) > 0, "packet numbers all 0")
    for name in NOT_CARRIED:
        check(table.column(name).null_count == table.num_rows, f"{name}: not null in every row")
        check(all(r[name] is None for r in records), f"{name}: not null in the JSON records")
    # The demo has a fault episode: the list column holds names, not just empty lists.
    check(any(r["faults"] for r in rows), "no faults in the demo's records")
    print("pyarrow_check: %d rows, schema, units and metadata as docs/RECORD-SCHEMA.md" % len(rows))
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
