#!/usr/bin/env bash
# The CAN log files of the common tools (testdata/dronecan/can-bus.{asc,blf,csv},
# can-bus-v1.1.trc, can-bus-v2.1.trc, can-bus.candump.txt, can-bus.candump-untimed.txt) are
# python-can's (the candump text written by the script): made again here by
# scripts/can-files.py with python-can from a fresh venv, they must be the files committed, and
# python-can must read each back as the candump log's frames (crates/hwfoc-cli/tests/can_files.rs
# runs the check; its other tests, each file decoded to the candump log's records, run in
# .ci/run). Called by .ci/run; runs on its own too.
set -euo pipefail
export CARGO_TERM_COLOR=never
cd "$(dirname "$0")/.."
venv=${TMPDIR:-/tmp}/hwfoc-ci-python-can-venv
python3 -m venv "$venv"
"$venv/bin/pip" install -q 'python-can>=4,<5'
"$venv/bin/python" -c 'import can; print("python-can", can.__version__)'
log=${TMPDIR:-/tmp}/hwfoc-ci-python-can.log
HWFOC_PYTHON_CAN_PY="$venv/bin/python" cargo test -p hwfoc-cli --test can_files \
  -- --include-ignored --nocapture 2>&1 | tee "$log"
grep -Eq "^test result: ok\. [1-9][0-9]* passed; 0 failed; 0 ignored" "$log" \
  || { echo "the CAN file tests did not all run and pass (see $log)" >&2; exit 1; }
grep -q "CAN files as written" "$log" \
  || { echo "the python-can check of the CAN files did not run (see $log)" >&2; exit 1; }
for f in can-bus.asc can-bus.blf can-bus-v2.1.trc can-bus-v1.1.trc can-bus.csv can-bus.candump.txt can-bus.candump-untimed.txt; do
  grep -q "^$f: 58 records as the candump log's" "$log" \
    || { echo "$f was not compared with the candump log (see $log)" >&2; exit 1; }
done
