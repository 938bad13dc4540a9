#!/usr/bin/env bash
# The DroneCAN output read by pydronecan (the `dronecan` Python package, with pyserial for its
# SLCAN driver): crates/hwfoc-bridge/tests/dronecan.rs relays the output's SLCAN through two
# pseudo-terminals to crates/hwfoc-bridge/tests/py/dronecan_check.py and compares every
# esc.Status it decodes with the records sent. The Wireshark dissector on pydronecan's frames
# (crates/hwfoc-cli/tests/wireshark.rs, with crates/hwfoc-cli/tests/py/dronecan_pcapng.py; it
# needs tshark too, which .ci/run installs), and the simulator's virtual CAN ESCs checked by it
# (below), `hwfoc can` setting up a pydronecan ESC stand-in, and CAN inputs read against
# pydronecan's frames (crates/hwfoc-cli/tests/can.rs, at the end). Called by .ci/run; runs on its
# own too.
set -euo pipefail
export CARGO_TERM_COLOR=never
cd "$(dirname "$0")/.."
venv=${TMPDIR:-/tmp}/hwfoc-ci-dronecan-venv
python3 -m venv "$venv"
"$venv/bin/pip" install -q dronecan pyserial
"$venv/bin/python" -c 'import dronecan, serial; print("dronecan", dronecan.__version__, "pyserial", serial.VERSION)'
# The pydronecan test is #[ignore]d in `cargo test`: here it runs (--include-ignored), and this
# checks that every test of the file passed and none was left out.
log=${TMPDIR:-/tmp}/hwfoc-ci-dronecan.log
HWFOC_DRONECAN_PY="$venv/bin/python" cargo test -p hwfoc-bridge --test dronecan \
  -- --include-ignored --nocapture 2>&1 | tee "$log"
grep -Eq "^test result: ok\. [1-9][0-9]* passed; 0 failed; 0 ignored" "$log" \
  || { echo "the DroneCAN tests did not all run and pass (see $log)" >&2; exit 1; }
grep -q "pydronecan decoded" "$log" || { echo "the pydronecan test did not run" >&2; exit 1; }
# The dissector's test on pydronecan's frames, by name (the file's other tests run in .ci/run).
log=${TMPDIR:-/tmp}/hwfoc-ci-dronecan-wireshark.log
HWFOC_DRONECAN_PY="$venv/bin/python" cargo test -p hwfoc-cli --test wireshark pydronecan \
  -- --ignored --nocapture 2>&1 | tee "$log"
grep -Eq "^test result: ok\. 1 passed; 0 failed; 0 ignored" "$log" \
  || { echo "the dissector's pydronecan test did not run and pass (see $log)" >&2; exit 1; }
grep -q "pydronecan frames dissected" "$log" \
  || { echo "the dissector's pydronecan test did not run" >&2; exit 1; }
# The simulator's virtual Hobbywing CAN ESCs (crates/hwfoc-sim/tests/can_pydronecan.rs, with
# crates/hwfoc-sim/tests/py/can_check.py): a candump log decoded by pydronecan as meant, and
# pydronecan's node setting them up over the SLCAN pty.
simlog=${TMPDIR:-/tmp}/hwfoc-ci-dronecan-sim.log
HWFOC_DRONECAN_PY="$venv/bin/python" cargo test -p hwfoc-sim --test can_pydronecan \
  -- --include-ignored --nocapture 2>&1 | tee "$simlog"
grep -Eq "^test result: ok\. 2 passed; 0 failed; 0 ignored" "$simlog" \
  || { echo "the simulator's pydronecan tests did not all run and pass (see $simlog)" >&2; exit 1; }
grep -q "as the simulator meant them" "$simlog" && grep -q "pydronecan over SLCAN" "$simlog" \
  || { echo "a simulator pydronecan test did not run (see $simlog)" >&2; exit 1; }
# The codec's DroneCAN test vectors (testdata/dronecan/vectors.txt) are pydronecan's: made again
# here by the installed package, they must be the file committed.
"$venv/bin/python" scripts/dronecan-vectors.py --check
# The CAN capture of pydronecan's frames the documentation's examples read
# (testdata/dronecan/pydronecan-frames.pcapng): made again here, it must be the file committed.
capture=${TMPDIR:-/tmp}/hwfoc-ci-dronecan-frames.pcapng
"$venv/bin/python" crates/hwfoc-cli/tests/py/dronecan_pcapng.py "$capture" > /dev/null
cmp "$capture" testdata/dronecan/pydronecan-frames.pcapng \
  || { echo "testdata/dronecan/pydronecan-frames.pcapng differs from what dronecan_pcapng.py writes" >&2; exit 1; }
# `hwfoc can` against an ESC stand-in written with pydronecan's node
# (crates/hwfoc-cli/tests/can_setup.rs, with crates/hwfoc-cli/tests/py/esc_standin.py): list,
# set --direction and set-id read back what it says. The file's other tests run in .ci/run.
canlog=${TMPDIR:-/tmp}/hwfoc-ci-dronecan-can.log
HWFOC_DRONECAN_PY="$venv/bin/python" cargo test -p hwfoc-cli --test can_setup pydronecan \
  -- --ignored --nocapture 2>&1 | tee "$canlog"
grep -Eq "^test result: ok\. 1 passed; 0 failed; 0 ignored" "$canlog" \
  || { echo "the hwfoc can pydronecan test did not run and pass (see $canlog)" >&2; exit 1; }
grep -q "pydronecan ESC stand-in set up by hwfoc can" "$canlog" \
  || { echo "the hwfoc can pydronecan test did not run (see $canlog)" >&2; exit 1; }
# CAN inputs read against pydronecan (crates/hwfoc-cli/tests/can.rs, with
# crates/hwfoc-cli/tests/py/can_frames.py): a bus of Hobbywing and standard DroneCAN ESCs it
# encodes, decoded by hwfoc from a candump log and live from SLCAN lines on a pty, compared
# record by record with the records the script says the schema makes.
canlog=${TMPDIR:-/tmp}/hwfoc-ci-dronecan-can-inputs.log
HWFOC_DRONECAN_PY="$venv/bin/python" cargo test -p hwfoc-cli --test can pydronecan \
  -- --ignored --nocapture 2>&1 | tee "$canlog"
grep -Eq "^test result: ok\. 2 passed; 0 failed; 0 ignored" "$canlog" \
  || { echo "the CAN input pydronecan tests did not all run and pass (see $canlog)" >&2; exit 1; }
grep -q "pydronecan candump log: " "$canlog" && grep -q "pydronecan SLCAN on a pty: " "$canlog" \
  || { echo "a CAN input pydronecan test did not run (see $canlog)" >&2; exit 1; }
# The candump log of that bus the golden tests and the Python tests read
# (testdata/dronecan/can-bus.log): made again here, it must be the file committed.
bus=${TMPDIR:-/tmp}/hwfoc-ci-dronecan-can-bus.log
"$venv/bin/python" crates/hwfoc-cli/tests/py/can_frames.py log "$bus" "$bus.expected.json"
cmp "$bus" testdata/dronecan/can-bus.log \
  || { echo "testdata/dronecan/can-bus.log differs from what can_frames.py writes" >&2; exit 1; }
