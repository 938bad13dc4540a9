"""Shared fixtures: the hwfoc command (the reference the package must agree with), the real
captures, and recordings made with the simulator."""

import datetime
import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

ROOT = Path(__file__).resolve().parents[2]
CAPTURES = sorted((ROOT / "testdata" / "captures").glob("*.csv"))


def _find_cli() -> str:
    """The hwfoc binary: $HWFOC_BIN, else the workspace's debug build (which `cargo test`
    leaves behind in CI)."""
    if os.environ.get("HWFOC_BIN"):
        return os.environ["HWFOC_BIN"]
    targets = [os.environ.get("CARGO_TARGET_DIR"), str(ROOT / "target")]
    for target in filter(None, targets):
        for profile in ("debug", "release"):
            path = Path(target) / profile / "hwfoc"
            if path.is_file():
                return str(path)
    raise RuntimeError("no hwfoc binary: build it (cargo build -p hwfoc-cli) or set HWFOC_BIN")


@pytest.fixture(scope="session")
def cli() -> str:
    return _find_cli()


def run_cli(cli, *args, check=True):
    """Runs the command; returns (stdout bytes, stderr text, exit code). With `check`, a
    failure is an error, except the one the command ends with when no input gave a data frame
    (exit 1 after its output: the Python functions return it empty, with their warnings)."""
    p = subprocess.run([cli, *map(str, args)], capture_output=True)
    err = p.stderr.decode()
    no_frames = p.returncode == 1 and "hwfoc: no data frame in any input" in err
    if check and p.returncode != 0 and not no_frames:
        raise AssertionError(f"hwfoc {args} failed: {err}")
    return p.stdout, err, p.returncode


def cli_error(cli, *args) -> str:
    """The message the command prints for a failing run (after `hwfoc: `)."""
    _, err, code = run_cli(cli, *args, check=False)
    assert code != 0, f"hwfoc {args} succeeded"
    lines = [line for line in err.splitlines() if line.startswith("hwfoc: ") and not line.startswith("hwfoc: warning")]
    assert lines, err
    return lines[-1][len("hwfoc: "):]


def cli_records(cli, *args):
    """`hwfoc decode --format jsonl ARGS` as a list of dicts."""
    out, _, _ = run_cli(cli, "decode", "--format", "jsonl", *args)
    return [json.loads(line) for line in out.splitlines()]


FLOAT32 = {
    "throttle_in_pct",
    "throttle_out_pct",
    "rpm",
    "voltage_v",
    "current_a",
    "phase_current_a",
    "mos_temp_c",
    "cap_temp_c",
    "motor_temp_c",
    "bec_temp_c",
    "bec_voltage_v",
    "bec_current_a",
}


# Columns of Arrow and Parquet only (record schema 4), after the JSON Lines record's.
BINARY_ONLY = ["time"]

EPOCH = datetime.datetime(1970, 1, 1, tzinfo=datetime.timezone.utc)


def same_instant(time, t_s):
    """Whether `time` (the `time` column's value) is `t_s` to the microsecond: null alike, or
    its whole microseconds within half of one of `t_s`'s."""
    if time is None or t_s is None:
        return time is None and t_s is None
    return abs((time - EPOCH) // datetime.timedelta(microseconds=1) - t_s * 1e6) <= 0.5


def assert_same_records(table: pa.Table, records):
    """The table holds exactly the command's JSON Lines records: same keys in order, same
    values (float32 columns compared as float32: JSON writes their shortest text), and `time`,
    the instant of `t_s`."""
    assert table.column_names == list(records[0].keys()) + BINARY_ONLY if records else True
    rows = table.to_pylist()
    assert len(rows) == len(records)
    for i, (got, want) in enumerate(zip(rows, records)):
        assert list(got) == list(want) + BINARY_ONLY, i
        assert same_instant(got["time"], want["t_s"]), (i, got["time"], want["t_s"])
        for key, value in want.items():
            g = got[key]
            if key in FLOAT32 and value is not None:
                assert np.float32(g) == np.float32(value), (i, key, g, value)
            else:
                assert g == value, (i, key, g, value)


def simulate(cli, path, *args):
    run_cli(cli, "simulate", "-q", "-o", path, *args)
    return path


@pytest.fixture(scope="session")
def sim_dir(tmp_path_factory, cli):
    """A few simulated inputs: a 3-ESC pcapng recording with faults and line noise, a raw
    stream, and the raw stream's bytes as a logic-analyser CSV is not made (the real captures
    are CSV)."""
    d = tmp_path_factory.mktemp("sim")
    simulate(cli, d / "three.pcapng", "--escs", "3", "--seed", "7", "--duration", "12",
             "--start-time", "1700000000", "--fault", "1:mos_overheat@3-5", "--fault", "over_current@8-8.5",
             "--drop-rate", "0.01", "--bit-error-rate", "1e-4", "--garbage-rate", "0.02")
    simulate(cli, d / "one.bin", "--seed", "3", "--duration", "40", "--fault", "input_voltage_low@2-3",
             "--cut-rate", "0.01")
    return d


FAULTS = ["mos_overheat", "over_current", "input_voltage_low", "cap_overheat", "motor_blocked", "throttle_signal_lost"]
WEEK = 7 * 86400
FLEET_NOW = 1_700_000_000 + 14 * 86400


@pytest.fixture(scope="session")
def fleet(tmp_path_factory, cli):
    """50 simulated recordings (pcapng): seeds, ESC counts (1-4), profiles, faults and line
    faults differ; start times spread over the two weeks before FLEET_NOW."""
    d = tmp_path_factory.mktemp("fleet")
    paths = []
    for k in range(50):
        args = ["--escs", str(1 + k % 4), "--seed", str(100 + k), "--duration", str(6 + k % 5),
                "--profile", ["steps", "ramp", "sine"][k % 3],
                "--start-time", str(FLEET_NOW - 14 * 86400 + k * 6 * 3600),
                "--ambient", str(15 + (k * 7) % 30)]
        if k % 3 == 0:
            args += ["--fault", f"{FAULTS[k % len(FAULTS)]}@1-2"]
        if k % 5 == 1:
            args += ["--fault", f"0:{FAULTS[(k + 1) % len(FAULTS)]}@2-2.5", "--fault", f"0:{FAULTS[(k + 2) % len(FAULTS)]}@3-4"]
        if k % 4 == 2:
            args += ["--drop-rate", "0.02", "--bit-error-rate", "2e-4"]
        paths.append(str(simulate(cli, d / f"rec-{k:02}.pcapng", *args)))
    return paths
