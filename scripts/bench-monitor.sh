#!/usr/bin/env bash
# CPU cost and screen latency of the `hwfoc monitor` dashboard with 16 ESCs at the real rate.
#
#   scripts/bench-monitor.sh [SECONDS] [ESCS]
#
# Builds the release binary, then runs the dashboard for SECONDS (default 60) in a tmux pane of
# 160x50, twice:
#   1. `hwfoc monitor --sim ESCS`: the virtual ESCs run inside the monitor process (their cost
#      is included);
#   2. `hwfoc monitor PTY...`: ESCS (default 16) virtual ESCs in a separate `hwfoc simulate --pty`
#      process, read through pseudo-terminals as real serial ports are (one reader thread each);
#   3. `hwfoc monitor slcan:PTY`: a CAN bus of ESCS virtual Hobbywing DroneCAN ESCs at their
#      message rates (StatusMsg1 and 2 at 50 Hz, StatusMsg3 at 10 Hz, NodeStatus at 1 Hz, at
#      500 kbit/s) behind one SLCAN adapter (`hwfoc simulate --protocol hw-can --pty`), hwfoc
#      asking them for their ids as a controller does.
# Each run ends by itself (--duration) and prints its --stats line: CPU time of the monitor
# process (user + system, from getrusage) as a share of one core, the redraws, and the delay
# from bytes taken in to the redraw that shows them reaching the terminal. Needs tmux.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
escs=${2:-16}
cargo build --release -p hwfoc-cli --quiet
bin=$PWD/target/release/hwfoc
work=$(mktemp -d)
socket=hwfoc-bench-$$
cleanup() {
  tmux -L "$socket" kill-server 2>/dev/null || true
  [ -n "${sim:-}" ] && kill "$sim" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
echo "$(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')); load average: $(cut -d' ' -f1-3 /proc/loadavg)"

run_in_tmux() {
  local label=$1
  shift
  tmux -L "$socket" new-session -d -s bench -x 160 -y 50 \
    "$* --stats --no-config --duration $seconds 2>$work/stats; echo done >> $work/stats"
  while ! grep -q '^done' "$work/stats" 2>/dev/null; do sleep 1; done
  echo "$label: $(grep 'monitor ran' "$work/stats")"
  rm -f "$work/stats"
  tmux -L "$socket" kill-server 2>/dev/null || true
}

run_in_tmux "--sim $escs (virtual ESCs in the process)" "$bin" monitor --sim "$escs"

"$bin" simulate --escs "$escs" --pty --link-dir "$work/escs" --quiet >"$work/ptys" &
sim=$!
while [ "$(wc -l <"$work/ptys")" -lt "$escs" ]; do sleep 0.2; done
ports=$(for i in $(seq 0 $((escs - 1))); do printf '%s ' "$work/escs/esc$i"; done)
# shellcheck disable=SC2086
run_in_tmux "$escs pseudo-terminals (ESCs in another process)" "$bin" monitor $ports
kill "$sim" 2>/dev/null || true

"$bin" simulate --protocol hw-can --escs "$escs" --pty >"$work/bus" &
sim=$!
until grep -q '^slcan: ' "$work/bus"; do sleep 0.2; done
run_in_tmux "a CAN bus of $escs Hobbywing ESCs (SLCAN pty)" "$bin" monitor "slcan:$(sed -n 's/^slcan: //p' "$work/bus")"
