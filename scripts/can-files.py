#!/usr/bin/env python3
"""The CAN log files of testdata/dronecan/ that hwfoc reads as inputs, written by python-can
(PyPI `python-can`, 4.x) from the frames of testdata/dronecan/can-bus.log (pydronecan's bus,
read with python-can's `LogReader`): the truth crates/hwfoc-cli/tests/can_files.rs decodes
each file against (the records of every file must be those of the candump -l log).

    python3 scripts/can-files.py           # write the files
    python3 scripts/can-files.py --check   # fail if a committed file differs from what this writes,
                                           # or python-can does not read it back as the log's frames

The files, each from the same 135 frames:

- can-bus.asc: python-can's ASCWriter (Vector ASC). Two things are set so that the file is the
  same each time and says its times right: the `date` line is the first frame's time (the
  writer puts the time it runs), and the milliseconds of the dates have their three digits
  (python-can 4.6 writes 7 ms as `.7`, which it and Vector's tools read as 700 ms).
- can-bus.blf: python-can's BLFWriter (Vector BLF, zlib-compressed log containers).
- can-bus-v2.1.trc: python-can's TRCWriter at version 2.1 (PEAK TRC); the header's line naming
  the file's absolute path names it by its file name.
- can-bus-v1.1.trc: PEAK TRC version 1.1, written here in PEAK's layout (python-can writes only
  1.0, which has no start time, and 2.1), and read back by python-can's TRCReader. Its offsets
  are to the microsecond, as 2.1's (PEAK's own 1.1 writes tenths of a millisecond, which would
  not keep the bus's microseconds).
- can-bus.csv: python-can's CSVWriter.
- can-bus.candump.txt: candump's own text with absolute times (`candump -ta can0`), and
  can-bus.candump-untimed.txt without them (`candump can0`), written here in can-utils' layout
  (python-can has no writer of it).

Dates are in UTC (ASC's are local times: the script sets TZ=UTC, and the test reads with it).
"""

import datetime
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ["TZ"] = "UTC"
time.tzset()

import can  # noqa: E402
import can.io.asc  # noqa: E402
from can.io.trc import TRCFileVersion  # noqa: E402

HERE = Path(__file__).resolve().parents[1] / "testdata" / "dronecan"
SOURCE = HERE / "can-bus.log"
FILES = [
    "can-bus.asc",
    "can-bus.blf",
    "can-bus-v2.1.trc",
    "can-bus-v1.1.trc",
    "can-bus.csv",
    "can-bus.candump.txt",
    "can-bus.candump-untimed.txt",
]


def frames():
    return list(can.LogReader(str(SOURCE)))


def write_with(writer, msgs):
    for m in msgs:
        writer.on_message_received(m)
    writer.stop()


def write_asc(path, msgs):
    first = msgs[0].timestamp

    class Fixed(datetime.datetime):
        @classmethod
        def now(cls, tz=None):
            return cls.fromtimestamp(first, tz)

    def header_date(self, dt):
        return dt.strftime(self.FORMAT_DATE.format(f"{dt.microsecond // 1000:03d}"))

    saved = (can.io.asc.datetime, can.ASCWriter._format_header_datetime)
    can.io.asc.datetime = Fixed
    can.ASCWriter._format_header_datetime = header_date
    try:
        write_with(can.ASCWriter(str(path)), msgs)
    finally:
        can.io.asc.datetime, can.ASCWriter._format_header_datetime = saved


def write_trc21(path, msgs):
    writer = can.TRCWriter(str(path))
    writer.file_version = TRCFileVersion.V2_1
    write_with(writer, msgs)
    text = path.read_bytes().replace(str(path).encode(), path.name.encode())
    path.write_bytes(text)


def write_trc11(path, msgs):
    start = msgs[0].timestamp
    days = (start - datetime.datetime(1899, 12, 30, tzinfo=datetime.timezone.utc).timestamp()) / 86400
    lines = [
        ";$FILEVERSION=1.1",
        f";$STARTTIME={days!r}",
        ";",
        f";   {path.name}",
        ";",
        f";   Start time: {datetime.datetime.fromtimestamp(start, datetime.timezone.utc)}",
        ";   Written by scripts/can-files.py in PEAK's layout of version 1.1",
        ";-------------------------------------------------------------------------------",
        ";   Message Number",
        ";   |         Time Offset (ms)",
        ";   |         |        Type",
        ";   |         |        |        ID (hex)",
        ";   |         |        |        |     Data Length",
        ";   |         |        |        |     |   Data Bytes (hex) ...",
        ";   |         |        |        |     |   |",
        ";---+--   ----+----  --+--  ----+---  +  -+ -- -- -- -- -- -- --",
    ]
    for n, m in enumerate(msgs, 1):
        arb = f"{m.arbitration_id:08X}" if m.is_extended_id else f"{m.arbitration_id:04X}"
        data = " ".join(f"{b:02X}" for b in m.data)
        offset = round((m.timestamp - start) * 1e6) / 1e3
        lines.append(f"{n:>6}){offset:>13.3f}  Rx     {arb:>8}  {m.dlc}  {data}".rstrip())
    path.write_bytes(("\r\n".join(lines) + "\r\n").encode())


def write_candump_text(path, msgs, timed=True):
    lines = []
    for m in msgs:
        arb = f"{m.arbitration_id:08X}" if m.is_extended_id else f"{m.arbitration_id:03X}"
        data = "  ".join([""] + [" ".join(f"{b:02X}" for b in m.data)]) if m.data else ""
        stamp = f" ({m.timestamp:.6f}) " if timed else " "
        lines.append(f"{stamp} {m.channel}  {arb}   [{m.dlc}]{data}")
    path.write_text("\n".join(lines) + "\n")


def write_all(folder):
    msgs = frames()
    write_asc(folder / "can-bus.asc", msgs)
    write_with(can.BLFWriter(str(folder / "can-bus.blf")), msgs)
    write_trc21(folder / "can-bus-v2.1.trc", msgs)
    write_trc11(folder / "can-bus-v1.1.trc", msgs)
    write_with(can.CSVWriter(str(folder / "can-bus.csv")), msgs)
    write_candump_text(folder / "can-bus.candump.txt", msgs)
    write_candump_text(folder / "can-bus.candump-untimed.txt", msgs, timed=False)
    return msgs


def read_back(path):
    """python-can's reading of a file, as (time in µs, id, extended, data)."""
    if path.suffix == ".asc":
        reader = can.ASCReader(str(path), relative_timestamp=False)
    else:
        reader = can.LogReader(str(path))
    return [(round(m.timestamp * 1e6), m.arbitration_id, m.is_extended_id, bytes(m.data)) for m in reader]


def main():
    if sys.argv[1:] == ["--check"]:
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            msgs = write_all(tmp)
            wanted = [(round(m.timestamp * 1e6), m.arbitration_id, m.is_extended_id, bytes(m.data)) for m in msgs]
            bad = [f for f in FILES if (tmp / f).read_bytes() != (HERE / f).read_bytes()]
            if bad:
                sys.exit(f"testdata/dronecan/{', '.join(bad)} differ from what scripts/can-files.py writes")
            for f in FILES:
                if f.endswith(".txt"):
                    continue
                if read_back(HERE / f) != wanted:
                    sys.exit(f"python-can does not read testdata/dronecan/{f} back as the log's frames")
        print(f"python-can {can.__version__}: {len(FILES)} CAN files as written, {len(msgs)} frames each")
    elif sys.argv[1:]:
        sys.exit(__doc__)
    else:
        write_all(HERE)


if __name__ == "__main__":
    main()
