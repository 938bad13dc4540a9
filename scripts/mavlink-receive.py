#!/usr/bin/env python3
"""Prints the ESC telemetry of `hwfoc bridge --mavlink` as JSON lines, with stock pymavlink
(`pip install pymavlink`), live or from a telemetry log:

    python3 mavlink-receive.py                       # UDP 14550: hwfoc bridge ... --mavlink udp
    python3 mavlink-receive.py udpin:0.0.0.0:14551   # hwfoc bridge ... --mavlink udp:HOST:14551
    python3 mavlink-receive.py flight.tlog           # hwfoc bridge ... --mavlink file:flight.tlog

One line per message: {"time": Unix seconds (received, or the log's), "type": "ESC_STATUS",
"sysid": 1, "compid": 158, then the message's fields}.

pymavlink's own dialects decode ESC_TELEMETRY_1_TO_4 and up, but not ESC_INFO (290) and
ESC_STATUS (291): MAVLink's common.xml marks them work in progress and ArduPilot's copy, which
pymavlink bundles, leaves them out, so pymavlink shows them as UNKNOWN_290 and UNKNOWN_291.
This script adds their definitions (from MAVLink's common.xml) to pymavlink's ardupilotmega
dialect with pymavlink's own generator, at start.
"""

import argparse
import contextlib
import importlib.util
import io
import json
import os
import sys
import tempfile

os.environ["MAVLINK20"] = "1"  # hwfoc sends MAVLink 2 (set before pymavlink is imported)
mavutil = mavgen = None  # pymavlink's modules, imported by main()

ESC_MESSAGES = """<?xml version="1.0"?>
<mavlink>
  <include>{ardupilotmega}</include>
  <messages>
    <message id="290" name="ESC_INFO">
      <description>ESC information for lower rate streaming.</description>
      <field type="uint8_t" name="index" instance="true">Index of the first ESC.</field>
      <field type="uint64_t" name="time_usec" units="us">Timestamp.</field>
      <field type="uint16_t" name="counter">Counter of data packets received.</field>
      <field type="uint8_t" name="count">Total number of ESCs.</field>
      <field type="uint8_t" name="connection_type">Connection type (1: serial).</field>
      <field type="uint8_t" name="info">Online bitmask.</field>
      <field type="uint16_t[4]" name="failure_flags">ESC_FAILURE_FLAGS.</field>
      <field type="uint32_t[4]" name="error_count">Errors since boot.</field>
      <field type="int16_t[4]" name="temperature" units="cdegC">Temperature.</field>
    </message>
    <message id="291" name="ESC_STATUS">
      <description>ESC information for higher rate streaming.</description>
      <field type="uint8_t" name="index" instance="true">Index of the first ESC.</field>
      <field type="uint64_t" name="time_usec" units="us">Timestamp.</field>
      <field type="int32_t[4]" name="rpm" units="rpm">RPM.</field>
      <field type="float[4]" name="voltage" units="V">Voltage.</field>
      <field type="float[4]" name="current" units="A">Current.</field>
    </message>
  </messages>
</mavlink>
"""


def esc_dialect(directory):
    """pymavlink's ardupilotmega dialect with ESC_INFO and ESC_STATUS, generated in directory."""
    bundled = os.path.join(os.path.dirname(mavutil.__file__), "dialects", "v20")
    xml = os.path.join(directory, "hwfoc_esc.xml")
    with open(xml, "w") as f:
        f.write(ESC_MESSAGES.format(ardupilotmega=os.path.join(bundled, "ardupilotmega.xml")))
    py = os.path.join(directory, "hwfoc_esc.py")
    opts = mavgen.Opts(py, wire_protocol="2.0", language="Python3", validate=False)
    with contextlib.redirect_stdout(io.StringIO()):  # the generator's progress
        mavgen.mavgen(opts, [xml])
    spec = importlib.util.spec_from_file_location("hwfoc_esc", py)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def arguments():
    """The command line: one optional SOURCE (`--help` prints the module's text)."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument(
        "source", nargs="?", default="udpin:0.0.0.0:14550", metavar="SOURCE",
        help="a pymavlink connection (udpin:HOST:PORT, a serial port) or a telemetry log "
             "(.tlog); default udpin:0.0.0.0:14550")
    return parser.parse_args()


def main():
    source = arguments().source
    # Imported once the arguments are read, so that --help needs no pymavlink.
    global mavutil, mavgen
    from pymavlink import mavutil
    from pymavlink.generator import mavgen
    with tempfile.TemporaryDirectory() as tmp:
        mavutil.mavlink = esc_dialect(tmp)  # the dialect of the connections made from here on
    log = os.path.isfile(source)
    connection = mavutil.mavlink_connection(source)
    print("receiving from", source, file=sys.stderr, flush=True)
    while True:
        msg = connection.recv_match(blocking=not log, timeout=1.0)
        if msg is None:
            if log:
                return 0  # the end of the log
            continue
        if not msg.get_type().startswith("ESC_"):
            continue
        fields = msg.to_dict()
        fields.pop("mavpackettype")
        line = {"time": msg._timestamp, "type": msg.get_type(),
                "sysid": msg.get_srcSystem(), "compid": msg.get_srcComponent()}
        line.update(fields)
        print(json.dumps(line), flush=True)


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit(0)
