"""Reads hwfoc's DroneCAN output as a ground station would: pydronecan's SLCAN driver on a
serial port, decoding uavcan.equipment.esc.Status, uavcan.equipment.esc.StatusExtended and
uavcan.protocol.NodeStatus.

    python dronecan_check.py PORT BITRATE ESC_STATUSES NODE_STATUSES TIMEOUT_S

Prints READY once the driver has set the adapter up, then one JSON object per message
decoded ({"type": "esc", ...}, {"type": "ext", ...} or {"type": "node", ...}; NaN as null), and
exits when it has
seen ESC_STATUSES esc.Status and NODE_STATUSES NodeStatus, or after TIMEOUT_S (exit code 1).
Run by crates/hwfoc-bridge/tests/dronecan.rs (through .ci/dronecan.sh).
"""

import json
import math
import sys
import time

import dronecan


def number(x):
    return None if math.isnan(x) else x


def main():
    port, bitrate, want_esc, want_node, timeout = sys.argv[1:6]
    want_esc, want_node, timeout = int(want_esc), int(want_node), float(timeout)
    # node_id=None: a passive node, which only listens.
    node = dronecan.make_node(port, node_id=None, bitrate=int(bitrate), baudrate=115200)
    seen = {"esc": 0, "node": 0}

    def on_esc(event):
        m = event.message
        print(json.dumps({
            "type": "esc",
            "source": event.transfer.source_node_id,
            "esc_index": m.esc_index,
            "error_count": m.error_count,
            "voltage": number(m.voltage),
            "current": number(m.current),
            "temperature": number(m.temperature),
            "rpm": m.rpm,
            "power_rating_pct": m.power_rating_pct,
        }), flush=True)
        seen["esc"] += 1

    def on_ext(event):
        m = event.message
        print(json.dumps({
            "type": "ext",
            "source": event.transfer.source_node_id,
            "esc_index": m.esc_index,
            "input_pct": m.input_pct,
            "output_pct": m.output_pct,
            "motor_temperature_degC": m.motor_temperature_degC,
            "motor_angle": m.motor_angle,
            "status_flags": m.status_flags,
        }), flush=True)

    def on_node(event):
        m = event.message
        print(json.dumps({
            "type": "node",
            "source": event.transfer.source_node_id,
            "uptime_sec": m.uptime_sec,
            "health": m.health,
            "mode": m.mode,
            "sub_mode": m.sub_mode,
            "vendor_specific_status_code": m.vendor_specific_status_code,
        }), flush=True)
        seen["node"] += 1

    node.add_handler(dronecan.uavcan.equipment.esc.Status, on_esc)
    node.add_handler(dronecan.uavcan.equipment.esc.StatusExtended, on_ext)
    node.add_handler(dronecan.uavcan.protocol.NodeStatus, on_node)
    print("READY", flush=True)
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        node.spin(0.05)
        if seen["esc"] >= want_esc and seen["node"] >= want_node:
            node.close()
            return 0
    print(json.dumps({"type": "timeout", "seen": seen}), flush=True)
    node.close()
    return 1


if __name__ == "__main__":
    sys.exit(main())
