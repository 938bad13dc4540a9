#!/usr/bin/env bash
# The bridge's figures (README, Performance): 16 virtual ESCs on ptys (`hwfoc simulate --pty`, real
# time) read by `hwfoc bridge` and written to all three outputs at once: DataLink frames and SLCAN
# to ptys, MAVLink to a UDP socket, each read and discarded by scripts/pty-sink.py. Prints the
# bridge's report (messages, failures, latency median and 99th percentile per output) and its CPU
# time over the wall time (the share of one core).
#
# Usage: scripts/bench-bridge.sh [SECONDS] [HWFOC]   (defaults: 60, target/release/hwfoc)
set -euo pipefail
seconds=${1:-60}
hwfoc=${2:-target/release/hwfoc}
dir=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$dir"' EXIT

"$hwfoc" simulate --escs 16 --pty --link-dir "$dir/escs" --profile sine --lead-in 1 \
  --duration $((seconds + 15)) >/dev/null 2>&1 &
python3 "$(dirname "$0")/pty-sink.py" 2 14599 >"$dir/ptys" 2>"$dir/sink" &
sink=$!
for _ in $(seq 100); do
  [ -e "$dir/escs/esc15" ] && [ "$(wc -l <"$dir/ptys")" -ge 2 ] && break
  sleep 0.1
done
datalink=$(sed -n 1p "$dir/ptys")
slcan=$(sed -n 2p "$dir/ptys")
ports=$(for i in $(seq 0 15); do printf '%s ' "$dir/escs/esc$i"; done)
# shellcheck disable=SC2086
/usr/bin/time -f "cpu %U s user %S s system %e s wall" "$hwfoc" bridge $ports \
  --datalink "$datalink" --mavlink udp:127.0.0.1:14599 --dronecan "slcan:$slcan" \
  --duration "$seconds" 2>"$dir/report" || true
cat "$dir/report"
awk '/^cpu/ { printf "CPU share of one core: %.1f %%\n", 100 * ($2 + $5) / $8 }' "$dir/report"
kill "$sink" && wait "$sink" 2>/dev/null || true
cat "$dir/sink"
