#!/usr/bin/env python3
"""Write pcapng recordings that stress how `hwfoc` reads many inputs (standard library only).

    make-many-recordings.py files DIR N [FRAMES]
        N recordings of one port (/dev/ttyUSB0), DIR/rec-00000.pcapng ... each FRAMES (default 10)
        data frames 50 ms apart, one packet per frame, the files continuing one another in time
        and in packet numbers (as `hwfoc record --rotate-size` cuts a long recording).
    make-many-recordings.py interfaces FILE N
        One recording declaring the same port (/dev/ttyUSB0) in N interface description blocks,
        N sections of one interface and one data frame each (recordings concatenated with `cat`),
        then, in the last section, N more interfaces of that name and a frame on the last.

The figures of issue 16 (items 13 and 14), with a release build:

    scripts/make-many-recordings.py files /tmp/many 10000
    (ulimit -n 256; /usr/bin/time -v target/release/hwfoc decode /tmp/many/*.pcapng -o /tmp/o.csv)
    scripts/make-many-recordings.py interfaces /tmp/ifaces.pcapng 1000000
    /usr/bin/time -v target/release/hwfoc decode /tmp/ifaces.pcapng -o /tmp/i.csv

(`/tmp/many/*.pcapng` is more than a shell passes to a program at once only past some 100 000
files; `find DIR -name '*.pcapng' -print0 | xargs -0 hwfoc decode` would split the list.)
"""

import os
import struct
import sys

DATA = struct.Struct(">4sHHHHHhhBBH")
HEADER = bytes([0x9B, 0x16, 0x01, 0x02])
PORT = b"/dev/ttyUSB0"
T0_NS = 1_700_000_000_000_000_000
FRAME_NS = 50_000_000


def data_frame(packet):
    """A data frame (see make-big-input.py): a little throttle, 25.2 V, 2 A."""
    body = DATA.pack(HEADER, packet & 0xFFFF, 200, 200, 1800, 252, 128, 0, 40, 30, 0)
    return body + struct.pack("<H", sum(body) & 0xFFFF)


def block(kind, body):
    body += b"\0" * (-len(body) % 4)
    length = len(body) + 12
    return struct.pack("<II", kind, length) + body + struct.pack("<I", length)


def option(code, value):
    return struct.pack("<HH", code, len(value)) + value + b"\0" * (-len(value) % 4)


SHB = block(0x0A0D0D0A, struct.pack("<IHHq", 0x1A2B3C4D, 1, 0, -1) + struct.pack("<HH", 0, 0))
IDB = block(
    1,
    struct.pack("<HHI", 147, 0, 0)
    + option(2, PORT)
    + option(8, struct.pack("<Q", 19200))
    + option(9, bytes([9]))
    + struct.pack("<HH", 0, 0),
)


def epb(iface, t_ns, data):
    return block(6, struct.pack("<IIIII", iface, t_ns >> 32, t_ns & 0xFFFFFFFF, len(data), len(data)) + data)


def files(directory, n, frames):
    os.makedirs(directory, exist_ok=True)
    packet = 0
    for k in range(n):
        out = bytearray(SHB + IDB)
        for _ in range(frames):
            out += epb(0, T0_NS + packet * FRAME_NS, data_frame(packet))
            packet += 1
        with open(os.path.join(directory, f"rec-{k:05}.pcapng"), "wb") as f:
            f.write(out)


def interfaces(path, n):
    with open(path, "wb") as f:
        section = SHB + IDB
        for k in range(n):
            f.write(section + epb(0, T0_NS + k * FRAME_NS, data_frame(k)))
        f.write(SHB + IDB * n + epb(n - 1, T0_NS + n * FRAME_NS, data_frame(n)))


def main():
    if len(sys.argv) >= 4 and sys.argv[1] == "files":
        frames = int(sys.argv[4]) if len(sys.argv) > 4 else 10
        files(sys.argv[2], int(sys.argv[3]), frames)
    elif len(sys.argv) == 4 and sys.argv[1] == "interfaces":
        interfaces(sys.argv[2], int(sys.argv[3]))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
