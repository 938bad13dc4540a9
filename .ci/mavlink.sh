#!/usr/bin/env bash
# The MAVLink output as ground stations' tooling decodes it: makes a Python virtual environment
# with pymavlink and runs hwfoc-bridge's test that has pymavlink (its bundled ardupilotmega
# dialect, and a parser its mavgen generates from crates/hwfoc-bridge/tests/mavlink-xml/) decode
# every message and compares them with the records. Called by .ci/run; runs alone as well.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TERM_COLOR=never

venv=${TMPDIR:-/tmp}/hwfoc-ci-mavlink-venv
start=$SECONDS
echo "::: mavlink-venv: python3 -m venv $venv; pip install pymavlink"
python3 -m venv "$venv"
"$venv/bin/pip" install -q --disable-pip-version-check 'pymavlink>=2.4.40'
"$venv/bin/python" -c 'import pymavlink; from pymavlink.generator import mavgen' \
  || { echo "pymavlink is not usable in $venv" >&2; exit 1; }
echo "::: mavlink-venv: ok ($((SECONDS - start)) s)"

start=$SECONDS
echo "::: mavlink-pymavlink: cargo test -p hwfoc-bridge --test mavlink_pymavlink"
# --nocapture: the test says how many messages of each kind pymavlink decoded.
HWFOC_PYMAVLINK="$venv/bin/python" cargo test -p hwfoc-bridge --test mavlink_pymavlink -- --nocapture 2>&1 \
  | tee "${TMPDIR:-/tmp}/hwfoc-ci-mavlink.log"
# The test passes when skipped: make sure it ran.
grep -q "pymavlink decoded and checked" "${TMPDIR:-/tmp}/hwfoc-ci-mavlink.log" \
  || { echo "the pymavlink test did not run" >&2; exit 1; }
echo "::: mavlink-pymavlink: ok ($((SECONDS - start)) s)"

# The bridge end to end: a recording replayed by `hwfoc bridge --mavlink`, received by pymavlink,
# with the values `hwfoc decode` gives for the same recording.
start=$SECONDS
echo "::: mavlink-bridge: cargo test -p hwfoc-cli --test bridge pymavlink"
HWFOC_PYMAVLINK="$venv/bin/python" cargo test -p hwfoc-cli --test bridge pymavlink -- --nocapture 2>&1 \
  | tee "${TMPDIR:-/tmp}/hwfoc-ci-mavlink-bridge.log"
grep -q "skipped" "${TMPDIR:-/tmp}/hwfoc-ci-mavlink-bridge.log" \
  && { echo "the bridge's pymavlink test did not run" >&2; exit 1; }
grep -q "1 passed" "${TMPDIR:-/tmp}/hwfoc-ci-mavlink-bridge.log" \
  || { echo "the bridge's pymavlink test did not pass" >&2; exit 1; }
echo "::: mavlink-bridge: ok ($((SECONDS - start)) s)"
