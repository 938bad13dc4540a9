"""Checks hwfoc's virtual Hobbywing CAN ESCs with pydronecan (PyPI `dronecan`), an
implementation hwfoc did not write.

    python can_check.py log LOG TRUTH
        Reads a candump log the simulator wrote, rebuilds pydronecan Frames, reassembles them
        with its TransferManager, decodes them, and checks each transfer against the
        simulator's ground truth (JSON Lines, one object per transfer, in the same order):
        type, source, destination, priority, transfer id and every field. Prints
        "pydronecan decoded N transfers as the simulator meant them" or fails.

    python can_check.py pty PORT NODE CHANNEL TIMEOUT_S
        pydronecan's node (node 100) on the SLCAN pseudo-terminal at 500 kbit/s: broadcasts
        GetEscID [0] and collects the answers, sends SetID (NODE, CHANNEL) to the first ESC
        that answered, then GetEscID again and GetMajorConfig to the new node. Prints one JSON
        object with what it got.

Run by crates/hwfoc-sim/tests/can_pydronecan.rs (through .ci/dronecan.sh).
"""

import json
import re
import sys
import time

import dronecan
from dronecan import transport

LINE = re.compile(r"^\((\d+)\.(\d+)\) (\S+) ([0-9A-Fa-f]{3}|[0-9A-Fa-f]{8})#([0-9A-Fa-f]*)$")


def value(v):
    try:
        return [value(x) for x in v]
    except TypeError:
        return v


def check_log(log, truth):
    with open(truth) as f:
        expected = [json.loads(line) for line in f if line.strip()]
    manager = transport.TransferManager()
    got = []
    with open(log) as f:
        for n, line in enumerate(f, 1):
            m = LINE.match(line.rstrip("\n"))
            assert m, f"{log}:{n}: not a candump line: {line!r}"
            can_id, data = m.group(4), bytes.fromhex(m.group(5))
            assert len(can_id) == 8, f"{log}:{n}: not an extended frame"
            frame = transport.Frame(int(can_id, 16), bytearray(data))
            frames = manager.receive_frame(frame)
            if frames:
                t = transport.Transfer()
                t.from_frames(frames)
                got.append(t)
    assert len(got) == len(expected), f"{len(got)} transfers decoded, {len(expected)} sent"
    for i, (t, e) in enumerate(zip(got, expected)):
        name = dronecan.get_dronecan_data_type(t.payload).full_name
        where = f"transfer {i} ({e['type']} from {e['source']})"
        assert name == e["type"], f"{where}: pydronecan decoded a {name}"
        assert t.source_node_id == e["source"], f"{where}: source {t.source_node_id}"
        assert t.transfer_id == e["transfer_id"], f"{where}: transfer id {t.transfer_id}"
        assert t.transfer_priority == e["priority"], f"{where}: priority {t.transfer_priority}"
        dest = t.dest_node_id if t.service_not_message else 0
        assert dest == e["destination"], f"{where}: destination {dest}"
        for field, want in e["fields"].items():
            have = value(getattr(t.payload, field))
            assert have == want, f"{where}: {field} is {have}, the simulator meant {want}"
    kinds = sorted({e["type"] for e in expected})
    print(f"pydronecan decoded {len(got)} transfers as the simulator meant them: {', '.join(kinds)}")


def check_pty(port, new_node, channel, timeout):
    hw = dronecan.com.hobbywing.esc
    node = dronecan.make_node(port, node_id=100, bitrate=500000, baudrate=115200)
    answers = []
    status_sources = set()
    node.add_handler(hw.GetEscID, lambda e: answers.append(
        [e.transfer.source_node_id, list(e.message.payload)]))
    node.add_handler(hw.StatusMsg1, lambda e: status_sources.add(e.transfer.source_node_id))

    def spin(seconds, until=lambda: False):
        end = time.monotonic() + seconds
        while time.monotonic() < end and not until():
            node.spin(0.02)

    out = {}
    node.broadcast(hw.GetEscID(payload=[0]))
    spin(1.0)
    out["first"] = sorted(a for a in answers if len(a[1]) == 2)
    assert out["first"], "no GetEscID answer"
    target = out["first"][0][0]
    responses = []
    node.request(hw.SetID.Request(node_id=new_node, throttle_channel=channel), target,
                 lambda e: responses.append(e))
    spin(timeout, lambda: responses)
    assert responses and responses[0] is not None, "no SetID response"
    r = responses[0]
    out["set_id"] = {"source": r.transfer.source_node_id, "node_id": r.response.node_id,
                     "throttle_channel": r.response.throttle_channel}
    answers.clear()
    status_sources.clear()
    node.broadcast(hw.GetEscID(payload=[0]))
    spin(1.0)
    out["after"] = sorted(a for a in answers if len(a[1]) == 2)
    out["status_sources"] = sorted(status_sources)
    config = []
    node.request(hw.GetMajorConfig.Request(option=0), new_node, lambda e: config.append(e))
    spin(timeout, lambda: config)
    assert config and config[0] is not None, "no GetMajorConfig response"
    c = config[0].response
    out["major_config"] = {"direction": int(c.direction), "throttle_channel": c.throttle_channel,
                           "MSG1_rate": c.MSG1_rate, "MSG2_rate": c.MSG2_rate}
    node.close()
    print(json.dumps(out), flush=True)


def main():
    if sys.argv[1] == "log":
        check_log(sys.argv[2], sys.argv[3])
    elif sys.argv[1] == "pty":
        check_pty(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), float(sys.argv[5]))
    else:
        sys.exit(f"unknown mode {sys.argv[1]!r}")


if __name__ == "__main__":
    main()
