#!/usr/bin/env python3
"""Writes testdata/hw5/vectors.txt: HW5 test vectors made from the spec (docs/HW5-AND-CAN.md,
"HW5") independently of the Rust code. Fields are packed with `struct` (little-endian) and the
CRC is crcmod's predefined 'modbus' (CRC-16/MODBUS). crates/hwfoc/tests/hw5.rs reads the file
and checks that the Rust codec encodes every telemetry vector to exactly these bytes, decodes
them to exactly these values, accepts every other frame as its kind, and rejects the corrupted
ones.

    python3 -m venv /tmp/hw5-venv && /tmp/hw5-venv/bin/pip install crcmod
    /tmp/hw5-venv/bin/python scripts/hw5-vectors.py            # rewrites the file
    /tmp/hw5-venv/bin/python scripts/hw5-vectors.py --check    # fails if it differs

Line format (one vector per line, `#` starts a comment):

    crc <data hex> <crc hex>
    telemetry <frame hex> crc=<hex> <field>=<value> ...
    frame <kind> <frame hex>
    corrupt <frame hex> <what>
"""

import random
import struct
import sys
from pathlib import Path

import crcmod.predefined

CRC16_MODBUS = crcmod.predefined.mkCrcFun("modbus")
assert CRC16_MODBUS(b"123456789") == 0x4B37, "crcmod's 'modbus' is not CRC-16/MODBUS"

OUT = Path(__file__).resolve().parent.parent / "testdata" / "hw5" / "vectors.txt"

# The spec's table: offset 0-5 `FE 01 00 03 30 5C`, 6 payload length 23, 7-8 `06 00`,
# 9 throttle u8, 10-11 unknown, 12 fault u8, 13-14 eRPM/10 u16, 15-16 voltage 0.1 V u16,
# 17-18 current 0.1 A u16, 19 ESC temp, 20 BEC temp, 21 motor temp (u8 degC), 22 BEC voltage
# 0.1 V u8, 23 BEC current 0.1 A u8, 24-29 unused `FF`, 30-31 CRC-16/MODBUS LE of bytes 0-29.
TELEMETRY = struct.Struct("<6sB2sB2sBHHHBBBBB6s")
assert TELEMETRY.size == 30

FIELDS = [
    "throttle",
    "unknown",
    "fault",
    "erpm_raw",
    "voltage_raw",
    "current_raw",
    "esc_temp",
    "bec_temp",
    "motor_temp",
    "bec_voltage_raw",
    "bec_current_raw",
]

FAULTS = [
    "motor_locked",
    "over_temperature",
    "throttle_not_zero_at_start",
    "throttle_signal_lost",
    "over_current",
    "low_voltage",
    "input_voltage_error",
    "motor_connection_error",
]

# Other frames: (kind, first three bytes, type, length), from the spec's list.
ESC = b"\xfe\x01\x00"
REQUEST = b"\x01\xfd\x03"
OTHER = [
    ("ping", ESC, 0x242C, 11),
    ("device_info", ESC, 0x252C, 73),
    ("reset", ESC, 0x022B, 10),
    ("parameters_read", ESC, 0x3835, 105),
    ("parameters_written", ESC, 0x3835, 58),
    ("parameters_write_error", ESC, 0x3835, 9),
    ("ping_request", REQUEST, 0x242C, 10),
]


def seal(body: bytes) -> bytes:
    """The frame: `body` and its CRC-16/MODBUS, low byte first."""
    return body + struct.pack("<H", CRC16_MODBUS(body))


def encode(v: dict) -> bytes:
    body = TELEMETRY.pack(
        b"\xfe\x01\x00\x03\x30\x5c",
        23,
        b"\x06\x00",
        v["throttle"],
        bytes(v["unknown"]),
        v["fault"],
        v["erpm_raw"],
        v["voltage_raw"],
        v["current_raw"],
        v["esc_temp"],
        v["bec_temp"],
        v["motor_temp"],
        v["bec_voltage_raw"],
        v["bec_current_raw"],
        b"\xff" * 6,
    )
    return seal(body)


def decode(frame: bytes) -> dict:
    """The script's own decoder, the inverse of `encode`, checking what it can."""
    assert len(frame) == 32
    assert CRC16_MODBUS(frame[:30]) == struct.unpack("<H", frame[30:])[0]
    (head, plen, b78, *values, unused) = TELEMETRY.unpack(frame[:30])
    assert head == b"\xfe\x01\x00\x03\x30\x5c" and plen == 23 and b78 == b"\x06\x00"
    assert unused == b"\xff" * 6
    v = dict(zip(FIELDS, values))
    v["unknown"] = list(v["unknown"])
    return v


def tenths(raw: int) -> str:
    """raw / 10 as an exact decimal."""
    return f"{raw // 10}.{raw % 10}"


def telemetry_line(v: dict) -> str:
    frame = encode(v)
    assert decode(frame) == v
    crc = struct.unpack("<H", frame[30:])[0]
    faults = "|".join(n for i, n in enumerate(FAULTS) if v["fault"] >> i & 1) or "-"
    values = [
        f"crc={crc:04X}",
        f"throttle={v['throttle']}",
        f"unknown={bytes(v['unknown']).hex().upper()}",
        f"fault={v['fault']}",
        f"erpm_raw={v['erpm_raw']}",
        f"voltage_raw={v['voltage_raw']}",
        f"current_raw={v['current_raw']}",
        f"esc_temp={v['esc_temp']}",
        f"bec_temp={v['bec_temp']}",
        f"motor_temp={v['motor_temp']}",
        f"bec_voltage_raw={v['bec_voltage_raw']}",
        f"bec_current_raw={v['bec_current_raw']}",
        f"erpm={v['erpm_raw'] * 10}",
        f"volts={tenths(v['voltage_raw'])}",
        f"amps={tenths(v['current_raw'])}",
        f"bec_volts={tenths(v['bec_voltage_raw'])}",
        f"bec_amps={tenths(v['bec_current_raw'])}",
        f"faults={faults}",
    ]
    return f"telemetry {frame.hex().upper()} " + " ".join(values)


def telemetry_values(rng: random.Random) -> dict:
    return {
        "throttle": rng.randrange(101),
        "unknown": [rng.randrange(256), rng.randrange(256)],
        "fault": rng.randrange(256) if rng.random() < 0.3 else 0,
        "erpm_raw": rng.randrange(65536),
        "voltage_raw": rng.randrange(65536),
        "current_raw": rng.randrange(65536),
        "esc_temp": rng.randrange(256),
        "bec_temp": rng.randrange(256),
        "motor_temp": rng.randrange(256),
        "bec_voltage_raw": rng.randrange(256),
        "bec_current_raw": rng.randrange(256),
    }


def lines() -> list:
    rng = random.Random(0x4857_35)
    out = [
        "# HW5 test vectors: written by scripts/hw5-vectors.py from docs/HW5-AND-CAN.md (struct + crcmod 'modbus'); do not edit.",
    ]

    out.append("# CRC-16/MODBUS of byte strings (crcmod), the check string first")
    out.append(f"crc {b'123456789'.hex().upper()} {CRC16_MODBUS(b'123456789'):04X}")
    out.append(f"crc - {CRC16_MODBUS(b''):04X}")
    for n in [1, 2, 3, 7, 8, 9, 30, 64, 103, 200]:
        data = bytes(rng.randrange(256) for _ in range(n))
        out.append(f"crc {data.hex().upper()} {CRC16_MODBUS(data):04X}")

    out.append("# Telemetry frames: the bytes, their CRC, the raw fields and the values in record units")
    fixed = [
        dict.fromkeys(FIELDS, 0) | {"unknown": [0, 0]},
        {
            "throttle": 255,
            "unknown": [255, 255],
            "fault": 255,
            "erpm_raw": 65535,
            "voltage_raw": 65535,
            "current_raw": 65535,
            "esc_temp": 255,
            "bec_temp": 255,
            "motor_temp": 255,
            "bec_voltage_raw": 255,
            "bec_current_raw": 255,
        },
        # A running 12S helicopter: 50.4 V, 35.7 A, 1800 rpm of a 10-pole motor's 9000 eRPM.
        {
            "throttle": 62,
            "unknown": [0, 0],
            "fault": 0,
            "erpm_raw": 900,
            "voltage_raw": 504,
            "current_raw": 357,
            "esc_temp": 48,
            "bec_temp": 41,
            "motor_temp": 55,
            "bec_voltage_raw": 84,
            "bec_current_raw": 12,
        },
        # Throttle cut: the ESC repeats its last current reading (the wire says 35.7 A).
        {
            "throttle": 0,
            "unknown": [0, 0],
            "fault": 0,
            "erpm_raw": 610,
            "voltage_raw": 509,
            "current_raw": 357,
            "esc_temp": 49,
            "bec_temp": 41,
            "motor_temp": 55,
            "bec_voltage_raw": 84,
            "bec_current_raw": 12,
        },
    ]
    for v in fixed:
        out.append(telemetry_line(v))
    for bit in range(8):
        out.append(telemetry_line(fixed[2] | {"fault": 1 << bit}))
    for _ in range(40):
        out.append(telemetry_line(telemetry_values(rng)))

    out.append("# Other frames, recognised and counted by kind: random payloads, sealed")
    for kind, envelope, ftype, length in OTHER:
        for _ in range(3):
            head = envelope + bytes([rng.randrange(256)]) + struct.pack("<H", ftype)
            payload = bytes(rng.randrange(256) for _ in range(length - 8))
            out.append(f"frame {kind} {seal(head + payload).hex().upper()}")
    # The ping request exactly as Rotorflight writes it.
    rotorflight_ping = bytes.fromhex("01FD03032C2400016060")
    assert seal(rotorflight_ping[:8]) == rotorflight_ping
    out.append(f"frame ping_request {rotorflight_ping.hex().upper()}")

    out.append("# Corrupted telemetry frames: one bit flipped, the CRC left as it was")
    base = encode(fixed[2])
    for bit in [0, 9, 17, 31, 48, 55, 72, 100, 150, 200, 239, 240, 250, 255]:
        frame = bytearray(base)
        frame[bit // 8] ^= 1 << (bit % 8)
        out.append(f"corrupt {frame.hex().upper()} bit{bit}")
    return out


def main() -> int:
    text = "\n".join(lines()) + "\n"
    if "--check" in sys.argv[1:]:
        if OUT.read_text() != text:
            print(f"{OUT} differs from what the script writes", file=sys.stderr)
            return 1
        print(f"{OUT} is up to date")
        return 0
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(text)
    print(f"wrote {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
