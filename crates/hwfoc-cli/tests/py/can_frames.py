#!/usr/bin/env python3
"""A DroneCAN bus of Hobbywing and standard ESCs made by pydronecan (PyPI `dronecan`), and the
records hwfoc must make of it (docs/RECORD-SCHEMA.md, version 3): the oracle of
crates/hwfoc-cli/tests/can.rs.

    python3 can_frames.py log OUT.log EXPECTED.json   # a candump -l log
    python3 can_frames.py slcan EXPECTED.json         # SLCAN lines on standard output, in real time

The bus (0.5 s; times in whole microseconds from 1700000000 s, Unix time):

- Hobbywing ESCs (`com.hobbywing.esc`) at nodes 11, 12 and 13: StatusMsg1 every 40 ms (rpm,
  pwm and the status word varied; node 12 turns counter-clockwise, status bit 14), StatusMsg2
  every 100 ms (node 12's current negative), StatusMsg3 every 250 ms from 0.15 s (so the first
  records take their MOSFET temperature from StatusMsg2), a NodeStatus each. At 0.2 s node
  127 asks GetEscID `[0]`; nodes 11 and 12 answer `[node, channel]` (channels 1 and 2), node
  13 never does.
- Standard DroneCAN ESCs (`uavcan.equipment.esc`) at nodes 40 (esc_index 3) and 41
  (esc_index 4): Status every 50 ms (three frames each, the two nodes' frames interleaved;
  negative current and rpm, node 41's voltage once NaN, once its CRC corrupted),
  StatusExtended every 100 ms from 0.12 s (motor temperature below zero).
- A message of a data type hwfoc does not know, from node 11.

Every transfer is encoded by pydronecan's own DSDL types and cut into CAN frames by its
`transport.Transfer.to_frames()`; the values expected are pydronecan's decoding of those frames
(`Transfer.from_frames()`: float16 fields hold the rounded value, NaN is NaN).

EXPECTED.json is a list of the records hwfoc must make, in the order of the frames that end
their transfers: each an object of the schema's columns (`t_s` the time of that frame in
seconds; for `slcan` times are hwfoc's receive times, so `t_s` is null there and the ages are
those the script meant), floats as computed in float32 where hwfoc's conversion is float32
(a temperature in kelvin - 273.15). The ages are computed here from the script's own times:
whole milliseconds between the frame that ended the slower message's transfer and the one
that ended the record's.

With `log`, the file is written deterministically (the `.ci/dronecan.sh` check that
testdata/dronecan/can-bus.log is this script's output depends on it).
"""

import json
import math
import random
import struct
import sys
import time

import dronecan
from dronecan import transport

HW = "com.hobbywing.esc."
ESC = "uavcan.equipment.esc."
T0_US = 1_700_000_000_000_000
DURATION_US = 500_000
UNKNOWN_TYPE = 12345
HW_NODES = {11: 1, 12: 2, 13: None}  # node -> throttle channel answered (None: no answer)
STD_NODES = {40: 3, 41: 4}  # node -> esc_index
ASKER = 127


def f32(x):
    """`x` rounded to float32."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def plain(value):
    if isinstance(value, transport.ArrayValue):
        return [plain(x) for x in value]
    if isinstance(value, transport.PrimitiveValue):
        return value.value
    return value


def frames_of(name, values, src, prio, tid):
    """pydronecan's frames of a message, and its decoding of them."""
    dtype = dronecan.TYPENAMES[name]
    t = transport.Transfer(
        payload=dtype(**values),
        source_node_id=src,
        service_not_message=False,
        transfer_id=tid,
        transfer_priority=prio,
    )
    frames = t.to_frames()
    back = transport.Transfer()
    back.from_frames(frames)
    decoded = {f: plain(getattr(back.payload, f)) for f in transport.get_fields(back.payload)}
    for k, v in values.items():
        if isinstance(v, float):
            assert math.isnan(v) == math.isnan(decoded[k]), (name, k)
        else:
            assert decoded[k] == v, (name, k, v, decoded[k])
    return [(f.message_id, bytes(f.bytes)) for f in frames], decoded


def schedule():
    """The bus's messages: (t_us of the first frame, name, values, source, priority, option),
    option "crc" for a transfer sent with its CRC corrupted."""
    rng = random.Random(20)
    out = []
    for node, channel in HW_NODES.items():
        off = node * 1000
        out.append((30_000 + off, "uavcan.protocol.NodeStatus",
                    dict(uptime_sec=100 + node, health=0, mode=0, sub_mode=0, vendor_specific_status_code=node),
                    node, 24, None))
        for k, t in enumerate(range(off, DURATION_US, 40_000)):
            rpm = 0 if k < 2 else min(65535, 900 * k + rng.randrange(0, 200) + (60000 if node == 13 and k > 8 else 0))
            pwm = 0 if k < 2 else min(1000, 80 * k + rng.randrange(0, 10))
            status = (0x4000 if node == 12 else 0) | (0x0021 if node == 13 and k % 3 == 0 else 0)
            out.append((t + rng.randrange(0, 300), HW + "StatusMsg1", dict(rpm=rpm, pwm=pwm, status=status),
                        node, 16, None))
        for k, t in enumerate(range(off + 5_000, DURATION_US, 100_000)):
            current = -(15 + k) if node == 12 else 120 * k + rng.randrange(0, 20)
            out.append((t + rng.randrange(0, 300), HW + "StatusMsg2",
                        dict(input_voltage=504 - k * 3, current=current, temperature=30 + k + node % 3),
                        node, 16, None))
        for k, t in enumerate(range(off + 150_000, DURATION_US, 250_000)):
            out.append((t + rng.randrange(0, 300), HW + "StatusMsg3",
                        dict(MOS_T=40 + k + node % 3, CAP_T=35 + k, Motor_T=50 + 2 * k + node),
                        node, 16, None))
    out.append((200_000, HW + "GetEscID", dict(payload=[0]), ASKER, 30, None))
    for node, channel in HW_NODES.items():
        if channel is not None:
            out.append((201_000 + node * 100, HW + "GetEscID", dict(payload=[node, channel]), node, 30, None))
    out.append((260_000, None, dict(), 11, 8, None))  # the unknown data type
    for node, index in STD_NODES.items():
        for k, t in enumerate(range(7_000, DURATION_US, 50_000)):
            voltage = float("nan") if node == 41 and k == 3 else 24.9 - 0.13 * k
            out.append((t, ESC + "Status",
                        dict(error_count=k * (node - 39), voltage=voltage, current=-1.7 + 3.1 * k,
                             temperature=300.0 + 2.3 * k, rpm=-2500 * k if node == 41 else 2500 * k,
                             power_rating_pct=min(127, 9 * k), esc_index=index),
                        node, 16, "crc" if node == 41 and k == 5 else None))
        for k, t in enumerate(range(120_000, DURATION_US, 100_000)):
            out.append((t + node * 100, ESC + "StatusExtended",
                        dict(input_pct=20 + 10 * k, output_pct=18 + 10 * k, motor_temperature_degC=-5 + 4 * k,
                             motor_angle=0, status_flags=k, esc_index=index),
                        node, 16, None))
    out.sort(key=lambda m: (m[0], m[3]))
    return out


def bus():
    """The frames, in time order: (t_us, can_id, data), and the transfers: (t_us of the last
    frame, name, decoded values, source, ok)."""
    frames = []
    transfers = []
    tids = {}
    for t, name, values, src, prio, option in schedule():
        tid = tids.get((src, name), 0)
        tids[(src, name)] = (tid + 1) % 32
        if name is None:
            can_id = (prio << 24) | (UNKNOWN_TYPE << 8) | src
            made, decoded = [(can_id, b"\x01\x02\x03" + bytes([0xC0 | tid]))], {}
        else:
            made, decoded = frames_of(name, values, src, prio, tid)
        if option == "crc":
            first = bytearray(made[0][1])
            first[0] ^= 0xFF
            made[0] = (made[0][0], bytes(first))
        # A multi-frame transfer's frames 200 us apart: two nodes' esc.Status sent at the same
        # time (the second 100 us later) interleave.
        if name == ESC + "Status" and src == 41:
            t += 100
        for k, (can_id, data) in enumerate(made):
            frames.append((t + 200 * k, can_id, data))
        transfers.append((t + 200 * (len(made) - 1), name, decoded, src, option is None))
    frames.sort(key=lambda f: f[0])
    transfers.sort(key=lambda x: x[0])
    assert len({f[0] for f in frames}) == len(frames), "two frames at one time"
    return frames, transfers


def age_ms(now, then):
    return None if then is None else (now - then) // 1000


def expected_records(transfers):
    """The records of docs/RECORD-SCHEMA.md hwfoc must make of the transfers. An ESC's number is
    its place on the bus: a Hobbywing node has, for the whole bus, the throttle channel - 1 it is
    answered with, its node id if never. A file is read ahead; live, hwfoc holds a node's records
    until its answer for up to 1 s of bus time, and the answers here come at 0.2 s, so the
    numbers are the same (live, held records come out when their node is placed)."""
    msg2, msg3, ext = {}, {}, {}
    records = []
    for t, name, v, src, ok in transfers:
        if not ok:
            continue
        if name == HW + "GetEscID":
            continue
        elif name == HW + "StatusMsg2":
            msg2[src] = (v, t)
        elif name == HW + "StatusMsg3":
            msg3[src] = (v, t)
        elif name == ESC + "StatusExtended":
            ext[src] = (v, t)
        elif name == HW + "StatusMsg1":
            m2, t2 = msg2.get(src, (None, None))
            m3, t3 = msg3.get(src, (None, None))
            mos = m3["MOS_T"] if m3 else (m2["temperature"] if m2 else None)
            final = HW_NODES[src]
            esc = final - 1 if final else src
            records.append(record(
                t, esc, "hw-can", src,
                throttle_out_pct=f32(v["pwm"] / 10), rpm=float(v["rpm"]),
                voltage_v=f32(m2["input_voltage"] / 10) if m2 else None,
                current_a=f32(m2["current"] / 10) if m2 else None,
                mos_temp_c=float(mos) if mos is not None else None,
                cap_temp_c=float(m3["CAP_T"]) if m3 else None,
                motor_temp_c=float(m3["Motor_T"]) if m3 else None,
                status=v["status"], msg2_age_ms=age_ms(t, t2), msg3_age_ms=age_ms(t, t3)))
        elif name == ESC + "Status":
            e, te = ext.get(src, (None, None))

            def half(x):
                return None if math.isnan(x) else f32(x)

            kelvin = half(v["temperature"])
            records.append(record(
                t, v["esc_index"], "dronecan", src,
                throttle_in_pct=float(e["input_pct"]) if e else None,
                throttle_out_pct=float(e["output_pct"]) if e else None,
                rpm=float(v["rpm"]), voltage_v=half(v["voltage"]), current_a=half(v["current"]),
                mos_temp_c=None if kelvin is None else f32(kelvin - f32(273.15)),
                motor_temp_c=float(e["motor_temperature_degC"]) if e else None,
                msg2_age_ms=age_ms(t, te)))
    return records


def record(t_us, esc, protocol, node, **values):
    r = dict(t_s=t_us / 1e6, esc=esc, protocol=protocol, packet=None, throttle_in_pct=None,
             throttle_out_pct=None, erpm=None, rpm=None, voltage_v=None, current_a=None, phase_current_a=None,
             mos_temp_c=None, cap_temp_c=None, motor_temp_c=None, bec_temp_c=None, bec_voltage_v=None,
             bec_current_a=None, status=None, faults=None, node=node, msg2_age_ms=None, msg3_age_ms=None)
    assert set(values) <= set(r), values
    r.update(values)
    return r


def candump(frames):
    lines = []
    for t, can_id, data in frames:
        t = T0_US + t
        lines.append(f"({t // 1_000_000:010}.{t % 1_000_000:06}) can0 {can_id:08X}#{data.hex().upper()}\n")
    return "".join(lines)


def slcan_line(can_id, data):
    return f"T{can_id:08X}{len(data)}{data.hex().upper()}\r".encode()


def main():
    mode = sys.argv[1] if len(sys.argv) > 1 else ""
    frames, transfers = bus()
    expected = expected_records(transfers)
    if mode == "log" and len(sys.argv) == 4:
        for r in expected:
            r["t_s"] = (T0_US + round(r["t_s"] * 1e6)) / 1e6
        with open(sys.argv[2], "w", newline="\n") as f:
            f.write(candump(frames))
        out = sys.argv[3]
    elif mode == "slcan" and len(sys.argv) == 3:
        for r in expected:
            r["t_s"] = None
        out = sys.argv[2]
    else:
        sys.exit(__doc__)
    with open(out, "w") as f:
        json.dump(expected, f, indent=0)
        f.write("\n")
    if mode == "slcan":
        # The frames at their times from now (the reader stamps them on arrival).
        start = time.monotonic()
        pipe = sys.stdout.buffer
        for t, can_id, data in frames:
            wait = start + t / 1e6 - time.monotonic()
            if wait > 0:
                time.sleep(wait)
            pipe.write(slcan_line(can_id, data))
            pipe.flush()


if __name__ == "__main__":
    main()
