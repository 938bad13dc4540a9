"""Throughput of hwfoc.read against a pure-Python decoder of the same frames, in one run.

    python python/bench/bench_read.py RAW_FILE [--python-mib N] [--scan]

hwfoc.read is timed on the whole file (the whole call: reading, decoding, building the Arrow
table). The pure-Python decoder (struct, the same checks and conversions, columns as Python
lists) is timed on the first N MiB (default 16) and its rate is taken as its rate on the whole
file (it is linear in the input). With --scan, the peak resident memory of hwfoc.scan over the
file is measured in a child process.
"""

import argparse
import os
import re
import resource
import struct
import subprocess
import sys
import time
from pathlib import Path

import hwfoc

ROOT = Path(__file__).resolve().parents[2]
HEADER = bytes([0x9B, 0x16, 0x01, 0x02])
FIELDS = struct.Struct(">HHHHHhhBBH")
HEADER_SUM = sum(HEADER)


def celsius_table():
    """Index: ADC code; value: degC or None, as the codec's table (crates/hwfoc/src/units/mod.rs)."""
    text = (ROOT / "crates/hwfoc/src/units/mod.rs").read_text()
    body = re.search(r"pub const ADC_TABLE: \[u8; 130\] = \[(.*?)\];", text, re.S).group(1)
    codes = [int(x) for x in re.findall(r"\b\d+\b", re.sub(r"//.*", "", body))]
    table = [None] * 256
    t = 0
    while t < len(codes):
        end = t
        while end + 1 < len(codes) and codes[end + 1] == codes[t]:
            end += 1
        table[codes[t]] = (t + end) / 2.0
        t = end + 1
    return table


FAULT_NAMES = [
    "input_voltage_high", "input_voltage_low", "over_current", "reserved_3",
    "throttle_signal_lost", "throttle_not_zeroed", "mos_overheat", "cap_overheat",
    "motor_blocked", "upper_bridge_open", "mos_short", "lower_bridge_open",
    "opamp_phase_c", "opamp_phase_b", "opamp_phase_a", "reserved_15",
]


def python_decode(data: bytes, current_scale=hwfoc.DEFAULT_CURRENT_SCALE, pole_pairs=hwfoc.DEFAULT_POLE_PAIRS,
                  gear_ratio=hwfoc.DEFAULT_GEAR_RATIO):
    """Data frames of raw bytes, by `bytes.find` of the header and `struct`: the columns of
    the record (as lists)."""
    temps = celsius_table()
    cols = {k: [] for k in hwfoc.record_schema().names}
    find, unpack = data.find, FIELDS.unpack_from
    rpm_div = 10.0 / (gear_ratio * pole_pairs)
    pos = find(HEADER)
    n = len(data)
    while 0 <= pos <= n - 24:
        frame = data[pos: pos + 24]
        if (HEADER_SUM + sum(frame[4:22])) & 0xFFFF != frame[22] | frame[23] << 8:
            pos = find(HEADER, pos + 1)
            continue
        packet, tin, tout, erpm, volt, cur, phase, mos, cap, status = unpack(frame, 4)
        cols["t_s"].append(None)
        cols["esc"].append(0)
        cols["packet"].append(packet)
        cols["throttle_in_pct"].append(tin * 100 / 1024)
        cols["throttle_out_pct"].append(tout * 100 / 1024)
        cols["erpm"].append(erpm * 10)
        cols["rpm"].append(erpm * rpm_div)
        cols["voltage_v"].append(volt / 10)
        cols["current_a"].append(cur / current_scale)
        cols["phase_current_a"].append(phase / current_scale)
        cols["mos_temp_c"].append(temps[mos])
        cols["cap_temp_c"].append(temps[cap])
        cols["status"].append(status)
        cols["faults"].append([FAULT_NAMES[b] for b in range(16) if status >> b & 1] if status else [])
        pos = find(HEADER, pos + 24)
    return cols


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("path")
    ap.add_argument("--python-mib", type=int, default=16)
    ap.add_argument("--scan", action="store_true")
    args = ap.parse_args()
    size = os.path.getsize(args.path)

    # The machine may be shared: the load average, and user CPU time beside the wall time (the
    # user CPU of all of hwfoc.read's threads, which other processes' load does not lengthen
    # much).
    print(f"load average: {' '.join(open('/proc/loadavg').read().split()[:3])}")
    t = time.perf_counter()
    cpu = resource.getrusage(resource.RUSAGE_SELF)
    table = hwfoc.read(args.path)
    rust_s = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_SELF)
    user_s, sys_s = after.ru_utime - cpu.ru_utime, after.ru_stime - cpu.ru_stime
    rows = table.num_rows
    del table
    print(f"hwfoc.read: {size / 1e6:.0f} MB in {rust_s:.2f} s = {size / rust_s / 1e6:.0f} MB/s of input, {rows} rows;"
          f" {user_s:.2f} s user ({size / user_s / 1e6:.0f} MB/s of input per user CPU second) + {sys_s:.2f} s system")

    with open(args.path, "rb") as f:
        part = f.read(args.python_mib << 20)
    t = time.perf_counter()
    cols = python_decode(part)
    py_s = time.perf_counter() - t
    # Same frames as hwfoc: compare on the slice.
    check = hwfoc.read(part)
    assert check.column("packet").to_pylist()[:1000] == cols["packet"][:1000]
    assert abs(check.num_rows - len(cols["packet"])) <= 1, (check.num_rows, len(cols["packet"]))
    py_rate = len(part) / py_s
    print(f"pure Python (struct): {len(part) / 1e6:.0f} MB in {py_s:.2f} s = {py_rate / 1e6:.1f} MB/s"
          f" (whole file at that rate: {size / py_rate:.0f} s)")
    print(f"hwfoc.read is {size / rust_s / py_rate:.0f}x the pure-Python decoder"
          f" ({size / user_s / py_rate:.0f}x by user CPU)")

    if args.scan:
        # VmHWM, not ru_maxrss: the latter is carried across exec from this process.
        script = (
            "import re, hwfoc\n"
            f"rows = sum(b.num_rows for b in hwfoc.scan({args.path!r}))\n"
            "hwm = re.search(r'VmHWM:\\s+(\\d+)', open('/proc/self/status').read()).group(1)\n"
            "print(rows, hwm)\n"
        )
        t = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
        scan_s = time.perf_counter() - t
        rows, rss_kib = map(int, out.split())
        print(f"hwfoc.scan: {rows} rows in {scan_s:.2f} s ({size / scan_s / 1e6:.0f} MB/s, interpreter start"
              f" included), peak RSS {rss_kib / 1024:.0f} MiB")
    print(f"(this process: peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB, read's table included)")


if __name__ == "__main__":
    main()
