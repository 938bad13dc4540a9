#!/usr/bin/env bash
# The DroneCAN output read by pydronecan (the `dronecan` Python package, with pyserial for its
# SLCAN driver): crates/hwfoc-bridge/tests/dronecan.rs relays the output's SLCAN through two
# pseudo-terminals to crates/hwfoc-bridge/tests/py/dronecan_check.py and compares every
# esc.Status it decodes with the records sent. Called by .ci/run; runs on its own too.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=${TMPDIR:-/tmp}/hwfoc-ci-dronecan-venv
python3 -m venv "$venv"
"$venv/bin/pip" install -q dronecan pyserial
"$venv/bin/python" -c 'import dronecan, serial; print("dronecan", dronecan.__version__, "pyserial", serial.VERSION)'
HWFOC_DRONECAN_PY="$venv/bin/python" cargo test -p hwfoc-bridge --test dronecan -- --nocapture
