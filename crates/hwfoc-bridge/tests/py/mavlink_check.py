#!/usr/bin/env python3
"""Receives hwfoc's MAVLink output as a ground station would, with pymavlink, and prints every
message it decodes as a JSON line, for tests/mavlink_pymavlink.rs to compare with the records.

Each datagram is decoded twice:
  - by a parser that pymavlink's mavgen generates, at start, from the message definitions vendored
    in tests/mavlink-xml/ (ardupilotmega.xml and its includes, common.xml among them): the only
    one that knows ESC_INFO and ESC_STATUS;
  - by the ardupilotmega dialect bundled with pymavlink (what MAVProxy and Mission Planner's
    definitions decode), which has HEARTBEAT and ESC_TELEMETRY_* but not ESC_INFO/ESC_STATUS.

Usage: mavlink_check.py XML_DIR
Prints "READY <port>" once listening on 127.0.0.1:<port>, then one JSON object per datagram:
  {"seq", "sysid", "compid", "name", "fields": {...}, "bundled": {...} | null}
and ends when its standard input is closed (after draining the socket).
"""

import importlib
import json
import os
import select
import socket
import subprocess
import sys
import tempfile


def generate(xml_dir, out_dir):
    """Generates a Python 3 MAVLink 2 parser from XML_DIR/ardupilotmega.xml with mavgen."""
    target = os.path.join(out_dir, "hwfoc_mavgen.py")
    subprocess.run(
        [sys.executable, "-m", "pymavlink.tools.mavgen", "--lang=Python3",
         "--wire-protocol=2.0", "--output=" + target,
         os.path.join(xml_dir, "ardupilotmega.xml")],
        check=True, stdout=subprocess.DEVNULL)
    sys.path.insert(0, out_dir)
    return importlib.import_module("hwfoc_mavgen")


def fields(msg):
    out = {}
    for name in msg.get_fieldnames():
        value = getattr(msg, name)
        out[name] = list(value) if isinstance(value, (list, tuple)) else value
    return out


def main():
    xml_dir = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        generated = generate(xml_dir, tmp)
        from pymavlink.dialects.v20 import ardupilotmega as bundled

        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind(("127.0.0.1", 0))
        print("READY", sock.getsockname()[1], flush=True)

        stdin_open = True
        while True:
            # Once stdin is closed, the socket is drained without waiting.
            ready = select.select([sock, sys.stdin], [], [], 10)[0] if stdin_open else [sock]
            if not ready:
                print(json.dumps({"error": "nothing for 10 s"}), flush=True)
                return 1
            if sys.stdin in ready:
                if sys.stdin.readline() == "":
                    stdin_open = False
                    sock.setblocking(False)
            if sock in ready:
                try:
                    data = sock.recv(1024)
                except BlockingIOError:
                    return 0
                # A parser per datagram: each datagram is exactly one MAVLink 2 frame.
                gen = generated.MAVLink(None)
                msgs = gen.parse_buffer(data)
                if not msgs or len(msgs) != 1:
                    print(json.dumps({"error": "not one frame", "bytes": data.hex()}), flush=True)
                    continue
                msg = msgs[0]
                record = {
                    "seq": msg.get_seq(),
                    "sysid": msg.get_srcSystem(),
                    "compid": msg.get_srcComponent(),
                    "name": msg.get_type(),
                    "fields": fields(msg),
                    "bundled": None,
                }
                try:
                    old = bundled.MAVLink(None).parse_buffer(data)
                    if old and old[0].get_type() == msg.get_type():
                        record["bundled"] = fields(old[0])
                except Exception:  # an unknown message id: the bundled dialect cannot decode it
                    pass
                print(json.dumps(record), flush=True)


if __name__ == "__main__":
    sys.exit(main())
