"""A Hobbywing DroneCAN ESC stand-in written with pydronecan's node (PyPI `dronecan`), for
`hwfoc can`'s tests: an implementation of the services hwfoc did not write.

    python esc_standin.py PORT NODE CHANNEL SECONDS

Opens the SLCAN adapter PORT at 500 kbit/s as node NODE, broadcasts StatusMsg1 (motor at rest)
at 50 Hz, answers GetEscID [0] with [node, channel], and serves SetID, SetDirection,
SetThrottleSource, SetLED, SetReportingFrequency, GetMajorConfig, GetMaintenanceInformation and
SelfTest per the DSDL, keeping its state (a SetID takes effect after its response). Prints
"stand-in ready" once open, and its final state as one JSON line when SECONDS have passed.

Run by crates/hwfoc-cli/tests/can_setup.rs (through .ci/dronecan.sh).
"""

import json
import sys
import time

import dronecan

hw = dronecan.com.hobbywing.esc


def main():
    port, node_id, channel, seconds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])
    node = dronecan.make_node(port, node_id=node_id, bitrate=500000, baudrate=115200)
    state = {"node_id": node_id, "channel": channel, "direction": 0, "source": 0,
             "led_color": 2, "led_blink": 0, "rates": {20050: 5, 20051: 5, 20052: 7}}
    pending = []

    def get_esc_id(e):
        if list(e.message.payload) == [0]:
            node.broadcast(hw.GetEscID(payload=[state["node_id"], state["channel"]]))

    def set_id(e):
        pending.append((e.request.node_id, e.request.throttle_channel))
        return hw.SetID.Response(node_id=e.request.node_id, throttle_channel=e.request.throttle_channel)

    def set_direction(e):
        if e.request.direction in (0, 1):
            state["direction"] = e.request.direction
        return hw.SetDirection.Response(direction=state["direction"])

    def set_source(e):
        if e.request.source in (0, 1):
            state["source"] = e.request.source
        return hw.SetThrottleSource.Response(source=state["source"])

    def set_led(e):
        state["led_color"], state["led_blink"] = e.request.color, e.request.blink
        return hw.SetLED.Response(option=e.request.option, color=e.request.color, blink=e.request.blink)

    def set_rate(e):
        msg = e.request.MSG_ID
        if e.request.option == 1 and msg in state["rates"]:
            state["rates"][msg] = e.request.rate
        return hw.SetReportingFrequency.Response(option=e.request.option, MSG_ID=msg,
                                                 rate=state["rates"].get(msg, 9))

    def major_config(e):
        return hw.GetMajorConfig.Response(
            direction=state["direction"], throttle_source=state["source"],
            throttle_channel=state["channel"], led_status=state["led_blink"],
            led_color=state["led_color"], MSG2_rate=state["rates"][20051],
            MSG1_rate=state["rates"][20050], positioning_angle=0, reserved=[0, 0])

    def maintenance(e):
        return hw.GetMaintenanceInformation.Response(total_rotation_time_min=1234,
                                                     time_since_maintainence_min=56)

    def self_test(e):
        return hw.SelfTest.Response(status=0)

    node.add_handler(hw.GetEscID, get_esc_id)
    for t, h in [(hw.SetID, set_id), (hw.SetDirection, set_direction),
                 (hw.SetThrottleSource, set_source), (hw.SetLED, set_led),
                 (hw.SetReportingFrequency, set_rate), (hw.GetMajorConfig, major_config),
                 (hw.GetMaintenanceInformation, maintenance), (hw.SelfTest, self_test)]:
        node.add_handler(t, h)
    print("stand-in ready", flush=True)
    end = time.monotonic() + seconds
    next_status = time.monotonic()
    while time.monotonic() < end:
        now = time.monotonic()
        if now >= next_status:
            node.broadcast(hw.StatusMsg1(rpm=0, pwm=0, status=state["direction"] << 14))
            next_status = now + 0.02
        node.spin(0.005)
        for new_id, new_channel in pending:
            # pydronecan lets a node id be set once: the stand-in takes the new one as a real
            # ESC does, after its response went out from the old one.
            node._node_id = new_id
            state["node_id"], state["channel"] = new_id, new_channel
        pending.clear()
    state["rates"] = {str(k): v for k, v in state["rates"].items()}
    print(json.dumps(state), flush=True)
    node.close()


if __name__ == "__main__":
    main()
