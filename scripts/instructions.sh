#!/usr/bin/env bash
# A guard on the work done, not on time: the instructions (valgrind's cachegrind) of four fixed
# jobs, each compared with its baseline in scripts/instructions.baseline.
#
#   scripts/instructions.sh [--update]
#
# The jobs, on inputs made here, the same bytes every time (scripts/make-big-input.py is
# deterministic; the codec's noisy stream is seeded):
#
# - `summary`: `hwfoc summary` of a 64 MiB raw input (read in two halves at once: the count is
#   both threads');
# - `parquet`: `hwfoc decode --format parquet -o FILE` of a 16 MiB raw input;
# - `python-read`: `hwfoc.read` of the same 16 MiB file in $PYTHON (default python3), less the
#   instructions of starting that interpreter and importing hwfoc; skipped, saying why, when
#   $PYTHON cannot import hwfoc;
# - `codec-noisy`: one bulk decode (`hwfoc::foc::frames`) of the codec's noisy ~8 MiB bench
#   stream (crates/hwfoc/benches/bulk.rs, `HWFOC_BULK_ONCE=noisy`): the run that decodes it once
#   less the one that only makes and checks it (`HWFOC_BULK_DECODES=0`).
#
# The binary is $HWFOC_BIN (default target/release/hwfoc, which it builds when missing); the
# bench is built with `cargo bench --no-run`. Prints each count beside its baseline; exits 1
# when one has grown by more than 10 % (or has no baseline). A deliberate growth updates the
# baseline (`--update` writes the counts measured) in the same commit, with its reason. Counts
# fallen by more than 10 % are told of: update the baseline so that the guard keeps the gain.
set -euo pipefail
cd "$(dirname "$0")/.."
update=false
[ "${1:-}" = --update ] && update=true
baseline=scripts/instructions.baseline
limit_pct=10
command -v valgrind >/dev/null || { echo "instructions: valgrind is not installed (apt-get install valgrind)" >&2; exit 1; }
work=${CARGO_TARGET_DIR:-target}/instructions
mkdir -p "$work"
bin=${HWFOC_BIN:-${CARGO_TARGET_DIR:-target}/release/hwfoc}
[ -x "$bin" ] || cargo build --release -p hwfoc-cli --quiet
python=${PYTHON:-python3}

# The instructions ("I refs") of a command under cachegrind, its other options before `--`.
count() {
  local out="$work/cachegrind.out" log="$work/cachegrind.log"
  local opts=()
  while [ "$1" != -- ]; do opts+=("$1"); shift; done
  shift
  valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file="$out" "${opts[@]}" \
    --log-file="$log" "$@" > /dev/null 2> "$log.stderr" \
    || { echo "instructions: $* failed under valgrind (see $log and $log.stderr)" >&2; exit 1; }
  awk '/^summary:/ { print $2 }' "$out"
}

input() {
  local file=$work/big-$1.bin
  [ -s "$file" ] || python3 scripts/make-big-input.py "$file" "$1" > /dev/null
  echo "$file"
}
big=$(input 64)
small=$(input 16)

declare -A got
got[summary]=$(count -- "$bin" summary "$big")
got[parquet]=$(count -- "$bin" decode --format parquet "$small" -o "$work/out.parquet")
rm -f "$work/out.parquet"
# The interpreter's counts are repeatable only with these two: numpy's OpenBLAS (imported with
# pyarrow) starts a thread per core whose busy waiting varied `import hwfoc` alone from 578 to
# 638 M instructions (and hwfoc.read's difference by +-10 %, which failed CI's fresh machine at
# +43.6 %); Python's string hashes, randomised per run, move the rest by some 0.05 %.
export OPENBLAS_NUM_THREADS=1 PYTHONHASHSEED=0
if why=$("$python" -c 'import hwfoc' 2>&1); then
  read_all=$(count -- "$python" -c 'import sys, hwfoc; hwfoc.read(sys.argv[1])' "$small")
  import_only=$(count -- "$python" -c 'import sys, hwfoc' "$small")
  got[python-read]=$((read_all - import_only))
else
  echo "python-read: skipped: $python cannot import hwfoc ($(echo "$why" | tail -n 1)); install it with pip install ./python"
fi
bench=$(cargo bench -p hwfoc --bench bulk --no-run --message-format=json 2> /dev/null \
  | sed -n 's/.*"executable":"\([^"]*\)".*/\1/p' | tail -n 1)
[ -x "$bench" ] || { echo "instructions: the codec's bulk bench did not build" >&2; exit 1; }
once=$(HWFOC_BULK_ONCE=noisy count -- "$bench")
none=$(HWFOC_BULK_ONCE=noisy HWFOC_BULK_DECODES=0 count -- "$bench")
got[codec-noisy]=$((once - none))

if $update; then
  {
    echo "# Instructions of scripts/instructions.sh's jobs (valgrind --tool=cachegrind), the baselines"
    echo "# it fails over by more than $limit_pct %. Updated by scripts/instructions.sh --update."
    for name in summary parquet python-read codec-noisy; do
      [ -n "${got[$name]:-}" ] && echo "$name ${got[$name]}"
    done
  } > "$baseline.new"
  # A job skipped here keeps its old baseline.
  if [ -z "${got[python-read]:-}" ] && grep -q '^python-read ' "$baseline" 2> /dev/null; then
    grep '^python-read ' "$baseline" >> "$baseline.new"
  fi
  mv "$baseline.new" "$baseline"
  echo "instructions: $baseline updated"
  cat "$baseline"
  exit 0
fi

status=0
for name in summary parquet python-read codec-noisy; do
  [ -n "${got[$name]:-}" ] || continue
  base=$(awk -v n="$name" '$1 == n { print $2 }' "$baseline" 2> /dev/null || true)
  if [ -z "$base" ]; then
    echo "$name: ${got[$name]} instructions, no baseline in $baseline"
    status=1
    continue
  fi
  verdict=$(awk -v g="${got[$name]}" -v b="$base" -v l="$limit_pct" 'BEGIN {
    d = 100 * (g - b) / b
    printf "%+.1f %% ", d
    if (d > l) print "FAIL: grown by more than " l " %"
    else if (d < -l) print "ok, fallen by more than " l " %: update the baseline to keep the gain"
    else print "ok"
  }')
  echo "$name: ${got[$name]} instructions, baseline $base: $verdict"
  case $verdict in *FAIL*) status=1 ;; esac
done
exit $status
