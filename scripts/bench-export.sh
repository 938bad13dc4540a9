#!/usr/bin/env bash
# Throughput and peak memory of `hwfoc decode` exports on a large synthetic input.
#
#   scripts/bench-export.sh [SIZE_MB] [RUNS] [OUT_DIR|null]
#   FORMATS="parquet csv" scripts/bench-export.sh ...
#
# Makes SIZE_MB (default 2048) MiB of raw telemetry with scripts/make-big-input.py (kept in
# target/bench/ for the next run), builds the release binary, then times
# `hwfoc decode --format FORMAT INPUT -o OUT_DIR/out.FORMAT` for each of FORMATS (default
# "parquet csv jsonl"), RUNS times each (default 3), with /usr/bin/time -v for the peak
# resident memory. The output goes to a file in OUT_DIR (default target/bench/), deleted before
# each run, or with `null` to /dev/null, which leaves the disk out of the figures (JSON Lines
# is about 9.5 times the size of the input, CSV 3 times, Parquet an eighth). Prints MB/s of input
# (MB = 10^6 bytes) for each run, with the share of the machine's CPU time that was idle or stolen
# by the hypervisor during it, and the best and median run per format. Other heavy processes on the
# machine skew the figures: the script prints the load average first; run it on a quiet machine.
# An output file past its first 16 MiB is written with direct I/O (see
# crates/hwfoc-io/src/write/file.rs), so disk figures include the disk's own throughput; compare
# variants by user + sys CPU time when the load average is not near zero.
#
# With BINS="PATH..." (binaries of other builds), each run times every one of them in turn
# (alternating builds in one sitting: the load changes alike for all) instead of building the
# release binary; each line names its binary.
set -euo pipefail
cd "$(dirname "$0")/.."
size_mb=${1:-2048}
runs=${2:-3}
bench=target/bench
out_dir=${3:-$bench}
formats=${FORMATS:-parquet csv jsonl}
declare -A all
mkdir -p "$bench"
[ "$out_dir" = null ] || mkdir -p "$out_dir"
input=$bench/big-$size_mb.bin
if [ ! -s "$input" ]; then
  python3 scripts/make-big-input.py "$input" "$size_mb"
fi
if [ -n "${BINS:-}" ]; then
  bins=$BINS
else
  cargo build --release -p hwfoc-cli --quiet
  bins=target/release/hwfoc
fi
bytes=$(stat -c %s "$input")
echo "input: $input, $bytes bytes; $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')); load average: $(cut -d' ' -f1-3 /proc/loadavg)"
# Read the input once so that every run finds it in the page cache.
cat "$input" > /dev/null
for format in $formats; do
  if [ "$out_dir" = null ]; then out=/dev/null; else out=$out_dir/out.$format; fi
  for bin in $bins; do all[$bin]=; done
  for run in $(seq "$runs"); do
  for bin in $bins; do
    [ "$out" = /dev/null ] || rm -f "$out"
    log=$(mktemp)
    cpu_before=$(head -1 /proc/stat)
    /usr/bin/time -v "$bin" decode --format "$format" "$input" -o "$out" 2> "$log"
    cpu_after=$(head -1 /proc/stat)
    wall=$(grep 'Elapsed (wall clock)' "$log" | awk '{print $NF}')
    rss_kb=$(grep 'Maximum resident set size' "$log" | awk '{print $NF}')
    user=$(grep 'User time' "$log" | awk '{print $NF}')
    sys=$(grep 'System time' "$log" | awk '{print $NF}')
    rm -f "$log"
    secs=$(echo "$wall" | awk -F: '{ s = 0; for (i = 1; i <= NF; i++) s = s * 60 + $i; print s }')
    mbps=$(awk -v b="$bytes" -v s="$secs" 'BEGIN { printf "%.0f", b / 1e6 / s }')
    if [ "$out" = /dev/null ]; then out_mb=-; else out_mb=$(($(stat -c %s "$out") / 1000000)); fi
    # Of the machine's CPU time during the run: idle (no thread of ours ready, or waiting for
    # the disk) and stolen (taken by the hypervisor for other guests: a noisy host).
    share=$(printf '%s\n%s\n' "$cpu_before" "$cpu_after" | awk '
      { for (i = 2; i <= 9; i++) v[NR, i] = $i }
      END {
        for (i = 2; i <= 9; i++) { d[i] = v[2, i] - v[1, i]; t += d[i] }
        printf "idle %.0f %%, stolen %.0f %%", 100 * (d[5] + d[6]) / t, 100 * d[9] / t
      }')
    printf '%-8s run %d: %6.2f s wall (%s s user, %s s sys; %s), %5s MB/s, peak RSS %d MB, output %s MB, %s\n' \
      "$format" "$run" "$secs" "$user" "$sys" "$share" "$mbps" $((rss_kb / 1024)) "$out_mb" "$bin"
    all[$bin]="${all[$bin]} $mbps"
  done
  done
  for bin in $bins; do
  echo "$format:${all[$bin]}" | awk -v bin="$bin" '{
    n = NF - 1; for (i = 2; i <= NF; i++) v[i - 1] = $i
    for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) if (v[j] > v[i]) { t = v[i]; v[i] = v[j]; v[j] = t }
    m = (n % 2) ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
    printf "%s best %d MB/s, median %d MB/s (%d runs), %s\n", $1, v[1], m, n, bin
  }'
  done
  [ "$out" = /dev/null ] || rm -f "$out"
done
