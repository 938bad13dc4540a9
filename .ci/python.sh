#!/usr/bin/env bash
# The Python package (python/): format and lints of its Rust crate, the wheel built and installed
# as a user installs it (`pip install ./python`: maturin, release build, abi3), then its tests
# against the hwfoc command (the debug build `cargo test --workspace` leaves in target/).
# Installs what it needs: a virtual environment with the test dependencies (pytest, pandas,
# polars, dask, pyspark, duckdb), and a Java runtime for Spark if there is none.
set -euo pipefail
cd "$(dirname "$0")/.."

step() {
  local name=$1
  shift
  echo "::: python/$name: $*"
  local start=$SECONDS
  "$@"
  echo "::: python/$name: ok ($((SECONDS - start)) s)"
}

venv=${TMPDIR:-/tmp}/hwfoc-ci-python
step venv python3 -m venv "$venv"
step pip "$venv/bin/pip" install -q --upgrade pip
if ! command -v java >/dev/null; then
  step apt-update apt-get update -q
  step java env DEBIAN_FRONTEND=noninteractive apt-get install -y -q default-jre-headless
fi
# The hwfoc command the tests compare with.
if [ -z "${HWFOC_BIN:-}" ]; then
  HWFOC_BIN=${CARGO_TARGET_DIR:-target}/debug/hwfoc
  [ -x "$HWFOC_BIN" ] || step cli cargo build -p hwfoc-cli
fi
export HWFOC_BIN
step format cargo fmt --manifest-path python/Cargo.toml -- --check
step clippy env PYO3_PYTHON="$venv/bin/python" cargo clippy --manifest-path python/Cargo.toml --all-targets -- -D warnings
step install "$venv/bin/pip" install -q "./python[test]"
# python-can: hwfoc.CanDecoder fed its Messages (python/tests/test_can.py, skipped without it).
step python-can "$venv/bin/pip" install -q 'python-can>=4,<5'
# pytest exits non-zero when no test ran, as when any failed.
step pytest "$venv/bin/python" -m pytest -q -p no:cacheprovider -rs python/tests 2>&1 | tee "${TMPDIR:-/tmp}/hwfoc-ci-pytest.log"
# The benchmark of docs/PERFORMANCE.md runs (on 16 MiB: a check that it works, not a figure).
bench_input=${TMPDIR:-/tmp}/hwfoc-ci-bench-16.bin
step bench-input python3 scripts/make-big-input.py "$bench_input" 16
step bench-read "$venv/bin/python" python/bench/bench_read.py "$bench_input" --python-mib 1 --scan
rm -f "$bench_input"
# Every test ran: what a test needs (python-can, polars, DuckDB) is installed here, and pytest -rs
# lists what was skipped, with the reason.
if grep -q "SKIPPED" "${TMPDIR:-/tmp}/hwfoc-ci-pytest.log"; then
  echo "python tests were skipped (see ${TMPDIR:-/tmp}/hwfoc-ci-pytest.log)" >&2
  exit 1
fi
