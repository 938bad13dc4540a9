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

# The tests that need pymavlink are #[ignore]d in `cargo test`: here they run (--include-ignored),
# and this checks that every test of the run passed and none was left out.
all_ran() {
  grep -Eq "^test result: ok\. [1-9][0-9]* passed; 0 failed; 0 ignored" "$1" \
    || { echo "$2: not every test ran and passed (see $1)" >&2; exit 1; }
}

start=$SECONDS
echo "::: mavlink-pymavlink: cargo test -p hwfoc-bridge --test mavlink_pymavlink"
# --nocapture: the test says how many messages of each kind pymavlink decoded.
log=${TMPDIR:-/tmp}/hwfoc-ci-mavlink.log
HWFOC_PYMAVLINK="$venv/bin/python" cargo test -p hwfoc-bridge --test mavlink_pymavlink \
  -- --include-ignored --nocapture 2>&1 | tee "$log"
all_ran "$log" "the pymavlink test"
echo "::: mavlink-pymavlink: ok ($((SECONDS - start)) s)"

# The bridge end to end: a recording replayed by `hwfoc bridge --mavlink`, received by pymavlink,
# with the values `hwfoc decode` gives for the same recording; the receiver people paste
# (scripts/mavlink-receive.py, stock pymavlink) live and from a tlog the bridge wrote; and
# pymavlink's mavlogdump.py on the tlog of a 30-minute flight, written as fast as it can be
# (mavlogdump_reads_a_half_hour_telemetry_log, which says how long that took).
start=$SECONDS
echo "::: mavlink-bridge: cargo test -p hwfoc-cli --test ground_stations"
log=${TMPDIR:-/tmp}/hwfoc-ci-mavlink-ground.log
HWFOC_PYMAVLINK="$venv/bin/python" cargo test -p hwfoc-cli --test ground_stations \
  -- --include-ignored --nocapture 2>&1 | tee "$log"
all_ran "$log" "the ground stations' tests"
echo "::: mavlink-bridge: ok ($((SECONDS - start)) s)"
