#!/usr/bin/env python3
"""Writes testdata/dronecan/vectors.txt: DroneCAN transfers encoded by pydronecan (PyPI
`dronecan`), the independent implementation the codec's `dronecan` module is checked against.
Every message and service of docs/HW5-AND-CAN.md ("Hobbywing DroneCAN ESCs") is encoded with
pydronecan's own DSDL types and cut into CAN frames by its `transport.Transfer.to_frames()`,
then decoded back by its `Transfer.from_frames()`; the file holds the frames and both the
values given and the values pydronecan decodes. crates/hwfoc/tests/dronecan.rs checks that the
Rust codec decodes every transfer's frames to exactly the decoded values and encodes the given
values (same node, priority and transfer id) to exactly the same frames.

    python3 -m venv /tmp/can-venv && /tmp/can-venv/bin/pip install dronecan
    /tmp/can-venv/bin/python scripts/dronecan-vectors.py            # rewrites the file
    /tmp/can-venv/bin/python scripts/dronecan-vectors.py --check    # fails if it differs

Line format (one record per line, `#` starts a comment, fields separated by one space):

    type <full name> <data type id> <signature hex> <message|service>
    crc <signature hex> <payload hex or -> <crc hex>
    transfer <full name> <message|request|response> prio=<p> src=<node> dst=<node or -> \
        tid=<t> <field>=<given>/<decoded> ... frames=<id hex>#<data hex>,...

Field values: integers in decimal, booleans 0/1, float16 fields as Python's repr of the value
(the given value is first rounded to float32, as pydronecan does before converting: `nan`,
`inf`, `-inf` included), arrays as values joined by `:` (`-` when empty). Field names are the
DSDL's. CAN ids are 29-bit extended ids.
"""

import math
import random
import struct
import sys
from pathlib import Path

import dronecan
from dronecan import transport
from dronecan.dsdl import common

OUT = Path(__file__).resolve().parent.parent / "testdata" / "dronecan" / "vectors.txt"

HW = "com.hobbywing.esc."
MESSAGES = [
    HW + "StatusMsg1",
    HW + "StatusMsg2",
    HW + "StatusMsg3",
    HW + "GetEscID",
    "uavcan.protocol.NodeStatus",
    "uavcan.equipment.esc.Status",
    "uavcan.equipment.esc.StatusExtended",
]
SERVICES = [
    HW + "SetID",
    HW + "SetBaud",
    HW + "SetLED",
    HW + "SetDirection",
    HW + "SetReportingFrequency",
    HW + "SetThrottleSource",
    HW + "SelfTest",
    HW + "SetAngle",
    HW + "GetMaintenanceInformation",
    HW + "GetMajorConfig",
]

assert common.crc16_from_bytes(b"123456789") == 0x29B1, "not CRC-16/CCITT-FALSE"


def f32(v):
    """The float32 pydronecan converts `v` from (its f16_from_f32 packs with struct '=f')."""
    if math.isnan(v) or math.isinf(v):
        return v
    if abs(v) > 3.4028234663852886e38:
        return math.copysign(math.inf, v)
    return struct.unpack("=f", struct.pack("=f", v))[0]


def text(v):
    if isinstance(v, bool):
        return str(int(v))
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, (list, tuple)):
        return ":".join(text(x) for x in v) if v else "-"
    return str(v)


def read_back(value):
    """A field of a decoded pydronecan object as a plain Python value."""
    if isinstance(value, transport.ArrayValue):
        return [read_back(x) for x in value]
    if isinstance(value, transport.PrimitiveValue):
        return value.value
    return value


def fields_of(obj):
    return list(transport.get_fields(obj).keys())


def transfer_line(name, form, obj, given, prio, src, dst, tid):
    service = form != "message"
    t = transport.Transfer(
        payload=obj,
        source_node_id=src,
        dest_node_id=dst if service else None,
        service_not_message=service,
        request_not_response=form == "request",
        transfer_id=tid,
        transfer_priority=prio,
    )
    frames = t.to_frames()
    back = transport.Transfer()
    back.from_frames(frames)
    assert back.service_not_message == service
    assert back.request_not_response == (form == "request") or not service
    assert back.source_node_id == src and back.transfer_id == tid
    decoded = back.payload
    parts = [
        "transfer",
        name,
        form,
        f"prio={prio}",
        f"src={src}",
        f"dst={dst if service else '-'}",
        f"tid={tid}",
    ]
    for field in fields_of(obj):
        g = given[field]
        d = read_back(getattr(decoded, field))
        parts.append(f"{field}={text(g)}/{text(d)}")
    parts.append(
        "frames="
        + ",".join(f"{f.message_id:08X}#{bytes(f.bytes).hex().upper()}" for f in frames)
    )
    return " ".join(parts)


def make(ctor, values):
    """A pydronecan object built from `values`; the values as given (floats rounded to
    float32 as pydronecan rounds them)."""
    obj = ctor(**values)
    given = {}
    for k, v in values.items():
        given[k] = f32(v) if isinstance(v, float) else v
    return obj, given


def field_specs(dtype, form):
    if form == "message":
        fields = dtype.fields
    elif form == "request":
        fields = dtype.request_fields
    else:
        fields = dtype.response_fields
    return fields


def random_value(rng, ftype):
    """A value for a field: extremes, zero and random values, some beyond the DSDL range where
    the Rust type holds them (to check saturation)."""
    from dronecan.dsdl import parser

    if isinstance(ftype, parser.ArrayType):
        n = rng.randint(0, ftype.max_size) if ftype.mode == parser.ArrayType.MODE_DYNAMIC else ftype.max_size
        return [random_value(rng, ftype.value_type) for _ in range(n)]
    kind = ftype.kind
    bits = ftype.bitlen
    if kind == parser.PrimitiveType.KIND_BOOLEAN:
        return rng.choice([False, True])
    if kind == parser.PrimitiveType.KIND_FLOAT:
        return rng.choice(
            [0.0, -0.0, 1.0, 65504.0, -65504.0, 70000.0, math.inf, -math.inf, math.nan, 6.0e-8,
             1.0e-5, rng.uniform(-100, 100), rng.uniform(0, 60), rng.uniform(200, 400),
             rng.uniform(-2000, 2000)]
        )
    lo, hi = ftype.value_range
    # the Rust type holding the field: u8/u16/u32 for unsigned, i16/i32 for signed
    if kind == parser.PrimitiveType.KIND_UNSIGNED_INT:
        rust_hi = 255 if bits <= 8 else 65535 if bits <= 16 else 0xFFFFFFFF
        return rng.choice([lo, hi, rng.randint(lo, hi), rng.randint(lo, hi), rng.randint(lo, rust_hi)])
    rust = 1 << 15 if bits <= 16 else 1 << 31
    return rng.choice([lo, hi, 0, rng.randint(lo, hi), rng.randint(lo, hi), rng.randint(-rust, rust - 1)])


def zero_value(ftype):
    from dronecan.dsdl import parser

    if isinstance(ftype, parser.ArrayType):
        return [0] * ftype.max_size if ftype.mode == parser.ArrayType.MODE_STATIC else []
    if ftype.kind == parser.PrimitiveType.KIND_BOOLEAN:
        return False
    if ftype.kind == parser.PrimitiveType.KIND_FLOAT:
        return 0.0
    return 0


def main():
    rng = random.Random(20)
    lines = [
        "# DroneCAN test vectors: written by scripts/dronecan-vectors.py with pydronecan "
        f"{dronecan.__version__}; do not edit.",
        "# Data types: full name, data type id, signature (pydronecan's get_data_type_signature()), kind",
    ]
    for name in MESSAGES + SERVICES:
        t = dronecan.TYPENAMES[name]
        kind = "service" if name in SERVICES else "message"
        lines.append(f"type {name} {t.default_dtid} {t.get_data_type_signature():016X} {kind}")

    lines.append("# Transfer CRCs: pydronecan's crc16_from_bytes(payload, initial=base_crc)")
    for name in MESSAGES + SERVICES:
        t = dronecan.TYPENAMES[name]
        sig = t.get_data_type_signature()
        base = common.crc16_from_bytes(struct.pack("<Q", sig))
        assert base == t.base_crc
        for n in [0, 1, 8, 14]:
            payload = bytes(rng.randrange(256) for _ in range(n))
            crc = common.crc16_from_bytes(payload, initial=base)
            lines.append(f"crc {sig:016X} {payload.hex().upper() or '-'} {crc:04X}")

    lines.append("# Transfers: pydronecan's to_frames() of each value, decoded back by from_frames()")
    tid_of = {}
    nodes = [1, 2, 7, 42, 125, 127]
    for name in MESSAGES + SERVICES:
        dtype = dronecan.TYPENAMES[name]
        forms = ["message"] if name in MESSAGES else ["request", "response"]
        for form in forms:
            specs = field_specs(dtype, form)
            if name in MESSAGES:
                ctor = dronecan.TYPENAMES[name]
            elif form == "request":
                ctor = dtype.Request
            else:
                ctor = dtype.Response
            cases = []
            # all zero, all extremes (low, high), then random values
            cases.append({f.name: zero_value(f.type) for f in specs})
            for _ in range(12):
                cases.append({f.name: random_value(rng, f.type) for f in specs})
            if name == HW + "GetEscID":
                # ArduPilot's request and typical answers
                cases += [{"payload": [0]}, {"payload": [1, 1]}, {"payload": [5, 3]}, {"payload": [1, 2, 3]}]
            if name == HW + "StatusMsg1":
                cases += [{"rpm": 65535, "pwm": 1000, "status": 0x4000}, {"rpm": 12345, "pwm": 500, "status": 0xFFFF}]
            if name == HW + "StatusMsg2":
                cases += [{"input_voltage": -32768, "current": 32767, "temperature": 255},
                          {"input_voltage": 504, "current": -12, "temperature": 41}]
            for values in cases:
                obj, given = make(ctor, values)
                key = (name, form)
                src = rng.choice(nodes)
                dst = rng.choice([n for n in nodes if n != src])
                prio = rng.choice([0, 8, 16, 24, 30, 31])
                tid = tid_of.get(key, rng.randrange(32))
                tid_of[key] = (tid + rng.choice([1, 1, 1, 5, 31])) % 32
                lines.append(transfer_line(name, form, obj, given, prio, src, dst, tid))

    text_out = "\n".join(lines) + "\n"
    if "--check" in sys.argv:
        if OUT.read_text() != text_out:
            sys.exit(f"{OUT} differs from what the script writes")
        return
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(text_out)
    print(f"wrote {OUT} ({len(lines)} lines)")


if __name__ == "__main__":
    main()
