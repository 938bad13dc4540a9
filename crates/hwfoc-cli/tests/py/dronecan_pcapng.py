#!/usr/bin/env python3
"""DroneCAN frames made by pydronecan (PyPI `dronecan`), written as a pcapng capture of a
SocketCAN interface (LINKTYPE_CAN_SOCKETCAN, 227), with what the Wireshark dissector
(crates/hwfoc-cli/wireshark/hwfoc.lua) must show for each of them.

    python3 dronecan_pcapng.py OUT.pcapng > expected.json

Every message and service of docs/HW5-AND-CAN.md ("Hobbywing DroneCAN ESCs") is encoded with
known values by pydronecan's own DSDL types and cut into CAN frames by its
`transport.Transfer.to_frames()`: the Hobbywing status messages, GetEscID (a request and an
answer), NodeStatus, esc.StatusExtended, each setup service's request and response, and
esc.Status (the multi-frame transfer: 3 frames) twice interleaved with another node's, once
with its CRC corrupted; then a message of a data type the dissector does not know. The pcapng
blocks are written here with `struct` (section header, one interface of link type 227, an
enhanced packet block per frame: the 16-byte SocketCAN record, can_id big-endian with the
extended-frame flag 0x80000000, the data length, 3 zero bytes, 8 data bytes).

Standard output is JSON: a list with one object per packet, `{"frame": <1-based number>,
"fields": {<Wireshark field>: [<value>, ...]}}`, each value a number (compared with a
tolerance), a string or a boolean; `[]` means the field must be absent. Field names follow
the dissector's rule: `dronecan.<type>.<DSDL field name, lower case>`, where <type> is
`hobbywing.<name>` for com.hobbywing.esc.<Name>, `esc.<name>` for uavcan.equipment.esc.<Name>,
and `nodestatus`. Values are pydronecan's own decoding of the frames (`Transfer.from_frames()`:
float16 fields hold the rounded value), checked here against the values given.
"""

import json
import struct
import sys

import dronecan
from dronecan import transport

HW = "com.hobbywing.esc."
LINKTYPE_CAN_SOCKETCAN = 227
CAN_EFF_FLAG = 0x80000000
UNKNOWN_TYPE = 12345


def prefix(name):
    """The dissector's field prefix for a data type."""
    for head, short in ((HW, "hobbywing."), ("uavcan.equipment.esc.", "esc."), ("uavcan.protocol.", "")):
        if name.startswith(head):
            return "dronecan." + short + name[len(head):].lower()
    raise ValueError(name)


def plain(value):
    if isinstance(value, transport.ArrayValue):
        return [plain(x) for x in value]
    if isinstance(value, transport.PrimitiveValue):
        return value.value
    return value


# (name, form, values, source, destination, priority, transfer id)
CASES = [
    (HW + "StatusMsg1", "message", dict(rpm=12345, pwm=500, status=0x4000 | 0x0021), 3, None, 16, 1),
    (HW + "StatusMsg1", "message", dict(rpm=2000, pwm=1000, status=0x0002), 4, None, 16, 2),
    (HW + "StatusMsg2", "message", dict(input_voltage=504, current=-12, temperature=41), 3, None, 16, 3),
    (HW + "StatusMsg3", "message", dict(MOS_T=45, CAP_T=38, Motor_T=61), 3, None, 16, 4),
    (HW + "GetEscID", "message", dict(payload=[0]), 10, None, 30, 5),
    (HW + "GetEscID", "message", dict(payload=[5, 3]), 5, None, 30, 6),
    ("uavcan.protocol.NodeStatus", "message",
     dict(uptime_sec=123456, health=1, mode=2, sub_mode=5, vendor_specific_status_code=0xBEEF), 3, None, 24, 7),
    ("uavcan.equipment.esc.StatusExtended", "message",
     dict(input_pct=42, output_pct=37, motor_temperature_degC=-20, motor_angle=300, status_flags=0x5A5A5,
          esc_index=6), 3, None, 16, 8),
    (HW + "SetID", "request", dict(node_id=5, throttle_channel=3), 10, 1, 24, 9),
    (HW + "SetID", "response", dict(node_id=5, throttle_channel=3), 1, 10, 24, 9),
    (HW + "SetBaud", "request", dict(baud=1), 10, 5, 24, 10),
    (HW + "SetBaud", "response", dict(), 5, 10, 24, 10),
    (HW + "SetLED", "request", dict(option=1, color=6, blink=2), 10, 5, 24, 11),
    (HW + "SetLED", "response", dict(option=1, color=6, blink=2), 5, 10, 24, 11),
    (HW + "SetDirection", "request", dict(direction=255), 10, 5, 24, 12),
    (HW + "SetDirection", "response", dict(direction=1), 5, 10, 24, 12),
    (HW + "SetReportingFrequency", "request", dict(option=1, MSG_ID=20051, rate=4), 10, 5, 24, 13),
    (HW + "SetReportingFrequency", "response", dict(option=1, MSG_ID=20051, rate=4), 5, 10, 24, 13),
    (HW + "SetThrottleSource", "request", dict(source=1), 10, 5, 24, 14),
    (HW + "SetThrottleSource", "response", dict(source=0), 5, 10, 24, 14),
    (HW + "SelfTest", "request", dict(), 10, 5, 24, 15),
    (HW + "SelfTest", "response", dict(status=1), 5, 10, 24, 15),
    (HW + "SetAngle", "request", dict(option=2, angle=1234), 10, 5, 24, 16),
    (HW + "SetAngle", "response", dict(option=2, angle=[1234, 40000]), 5, 10, 24, 16),
    (HW + "GetMaintenanceInformation", "request", dict(option=1), 10, 5, 24, 17),
    (HW + "GetMaintenanceInformation", "response",
     dict(total_rotation_time_min=3000000, time_since_maintainence_min=70000), 5, 10, 24, 17),
    (HW + "GetMajorConfig", "request", dict(option=0), 10, 5, 24, 18),
    (HW + "GetMajorConfig", "response",
     dict(direction=True, throttle_source=False, throttle_channel=37, led_status=19, led_color=5, MSG2_rate=9,
          MSG1_rate=3, positioning_angle=4321, reserved=[0xAB, 0xCD]), 5, 10, 24, 18),
]
# esc.Status (multi-frame): values, source, transfer id; the first two interleaved frame by
# frame, the third with its CRC corrupted.
ESC_STATUS = [
    (dict(error_count=7, voltage=16.5, current=-2.25, temperature=313.15, rpm=-1234, power_rating_pct=55,
          esc_index=3), 20, 21),
    (dict(error_count=123456789, voltage=50.4, current=31.7, temperature=350.0, rpm=131071, power_rating_pct=127,
          esc_index=31), 21, 0),
    (dict(error_count=1, voltage=12.0, current=1.5, temperature=300.0, rpm=-131072, power_rating_pct=0,
          esc_index=0), 20, 22),
]


def transfer(name, form, values, src, dst, prio, tid):
    dtype = dronecan.TYPENAMES[name]
    ctor = dtype if form == "message" else (dtype.Request if form == "request" else dtype.Response)
    service = form != "message"
    t = transport.Transfer(
        payload=ctor(**values),
        source_node_id=src,
        dest_node_id=dst,
        service_not_message=service,
        request_not_response=form == "request",
        transfer_id=tid,
        transfer_priority=prio,
    )
    frames = t.to_frames()
    back = transport.Transfer()
    back.from_frames(frames)
    decoded = {f: plain(getattr(back.payload, f)) for f in transport.get_fields(back.payload)}
    for k, v in values.items():
        if not isinstance(v, float):
            assert decoded[k] == v, (name, k, v, decoded[k])
    return dtype, frames, decoded


def header_fields(name, form, dtid, src, dst, prio, frame):
    tail = frame.bytes[-1]
    return {
        "dronecan.priority": [prio],
        "dronecan.type_id": [dtid],
        "dronecan.type_name": [name] if name else [],
        "dronecan.kind": [form],
        "dronecan.source": [src],
        "dronecan.destination": [dst] if dst is not None else [],
        "dronecan.tail.start": [bool(tail & 0x80)],
        "dronecan.tail.end": [bool(tail & 0x40)],
        "dronecan.tail.toggle": [bool(tail & 0x20)],
        "dronecan.tail.transfer_id": [tail & 0x1F],
    }


def payload_fields(name, decoded):
    """What the dissector shows of a decoded payload."""
    p = prefix(name)
    out = {}
    for field, value in decoded.items():
        key = f"{p}.{field.lower()}"
        out[key] = value if isinstance(value, list) else [value]
    if name == HW + "StatusMsg1":
        out[p + ".direction"] = ["CCW" if decoded["status"] & 0x4000 else "CW"]
    if name == HW + "StatusMsg2":
        out[p + ".input_voltage"] = [decoded["input_voltage"] / 10]
        out[p + ".current"] = [decoded["current"] / 10]
    if name == HW + "GetEscID":
        payload = decoded["payload"]
        answer = len(payload) == 2
        out[p + ".what"] = ["request" if payload == [0] else "answer" if answer else "other"]
        out[p + ".node_id"] = [payload[0]] if answer else []
        out[p + ".throttle_channel"] = [payload[1]] if answer else []
    return out


def record(can_id, data, extended=True):
    flags = CAN_EFF_FLAG if extended else 0
    return struct.pack(">IB3x", can_id | flags, len(data)) + bytes(data) + bytes(8 - len(data))


def pcapng(records):
    def block(kind, body):
        body += bytes(-len(body) % 4)
        n = len(body) + 12
        return struct.pack("<II", kind, n) + body + struct.pack("<I", n)

    out = block(0x0A0D0D0A, struct.pack("<IHHq", 0x1A2B3C4D, 1, 0, -1))
    # if_tsresol (9): microseconds, the default, written out; then the end of options
    options = struct.pack("<HHB3x", 9, 1, 6) + struct.pack("<HH", 0, 0)
    out += block(1, struct.pack("<HHI", LINKTYPE_CAN_SOCKETCAN, 0, 16) + options)
    t_us = 1_700_000_000_000_000
    for i, rec in enumerate(records):
        t = t_us + i * 1000
        out += block(6, struct.pack("<IIIII", 0, t >> 32, t & 0xFFFFFFFF, len(rec), len(rec)) + rec)
    return out


def main():
    records = []
    expected = []

    def add(frame, fields):
        records.append(record(frame.message_id, frame.bytes))
        expected.append({"frame": len(records), "fields": fields})

    for name, form, values, src, dst, prio, tid in CASES:
        dtype, frames, decoded = transfer(name, form, values, src, dst, prio, tid)
        assert len(frames) == 1, name
        fields = header_fields(name, form, dtype.default_dtid, src, dst, prio, frames[0])
        fields.update(payload_fields(name, decoded))
        add(frames[0], fields)

    name = "uavcan.equipment.esc.Status"
    made = [transfer(name, "message", v, src, None, 16, tid) for v, src, tid in ESC_STATUS]
    # the third transfer's CRC (the first two bytes of its first frame) corrupted
    bad_first = made[2][1][0]
    bad_first.bytes = bytearray(bad_first.bytes)
    bad_first.bytes[0] ^= 0xFF
    order = [(0, 0), (1, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 0), (2, 1), (2, 2)]
    for which, k in order:
        dtype, frames, decoded = made[which]
        src = ESC_STATUS[which][1]
        fields = header_fields(name, "message", dtype.default_dtid, src, None, 16, frames[k])
        last = k == len(frames) - 1
        fields["dronecan.transfer.frame_index"] = [k + 1]
        if last:
            good = which != 2
            fields["dronecan.crc.status"] = [1 if good else 0]
            if good:
                fields.update(payload_fields(name, decoded))
            else:
                fields[prefix(name) + ".rpm"] = []
        else:
            fields["dronecan.crc.status"] = []
            fields[prefix(name) + ".rpm"] = []
        add(frames[k], fields)

    # a message of a data type the dissector does not know: shown with its id only
    prio, src, tid = 8, 9, 3
    can_id = (prio << 24) | (UNKNOWN_TYPE << 8) | src
    frame = transport.Frame(can_id, bytearray(b"\x01\x02\x03" + bytes([0xC0 | tid])))
    fields = header_fields(None, "message", UNKNOWN_TYPE, src, None, prio, frame)
    add(frame, fields)

    with open(sys.argv[1], "wb") as f:
        f.write(pcapng(records))
    json.dump(expected, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()
