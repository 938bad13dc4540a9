#!/usr/bin/env bash
# Bulk decoding of a CAN bus's log: frames per second read from a `candump -l` file.
#
#   scripts/bench-can.sh [ESCS] [SECONDS] [RUNS]
#
# Builds the release binary, writes a log of ESCS (default 16) virtual Hobbywing DroneCAN ESCs
# over SECONDS (default 600) of simulated time (`hwfoc simulate --protocol hw-can`: StatusMsg1
# and 2 at 50 Hz, StatusMsg3 at 10 Hz, NodeStatus at 1 Hz each, a controller asking for ids),
# then times RUNS (default 5) runs each of `hwfoc summary` and of `hwfoc decode` to JSON Lines
# (written to /dev/null) on it, and prints each run's wall time, frames per second, user CPU and
# peak memory, and the medians.
set -euo pipefail
cd "$(dirname "$0")/.."
escs=${1:-16}
seconds=${2:-600}
runs=${3:-5}
cargo build --release -p hwfoc-cli --quiet
bin=$PWD/target/release/hwfoc
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "$(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')); load average: $(cut -d' ' -f1-3 /proc/loadavg)"
"$bin" simulate --protocol hw-can --escs "$escs" --duration "$seconds" -o "$work/bus.log" >/dev/null
frames=$(wc -l <"$work/bus.log")
echo "log: $frames frames, $(stat -c %s "$work/bus.log") bytes, $escs ESCs, $seconds s"
for what in summary decode; do
  walls=()
  for _ in $(seq "$runs"); do
    /usr/bin/time -f '%e %U %M' -o "$work/time" "$bin" "$what" "$work/bus.log" >/dev/null
    read -r wall user kb <"$work/time"
    walls+=("$wall")
    awk -v w="$wall" -v u="$user" -v k="$kb" -v f="$frames" -v n="$what" \
      'BEGIN { printf "%-8s %6.2f s  %9.0f frames/s  user %.2f s  peak %.1f MB\n", n, w, f / w, u, k / 1000 }'
  done
  median=$(printf '%s\n' "${walls[@]}" | sort -n | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')
  awk -v w="$median" -v f="$frames" -v n="$what" \
    'BEGIN { printf "%-8s median %.2f s: %.0f frames/s\n", n, w, f / w }'
done
