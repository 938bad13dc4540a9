#!/usr/bin/env bash
# The size of a release binary of hwfoc as built and stripped of every symbol, checked against a
# limit: what `cargo install` puts on a machine (and a Raspberry Pi's SD card) stays small.
#
#   scripts/binary-size.sh BINARY [LIMIT_BYTES]
#
# BINARY is a release build (target/release/hwfoc, or target/TRIPLE/release/hwfoc): the release
# profile builds it without debug information or symbols (the workspace's Cargo.toml).
# LIMIT_BYTES (default 16000000, 16 MB) applies to the
# binary as built (what `cargo install` installs: debug information creeping back into the
# release profile fails here) and to a copy stripped of every symbol, made with `strip` (or
# aarch64-linux-gnu-strip for an AArch64 binary) in a temporary file. Prints both sizes; exits 1
# over the limit.
set -euo pipefail
bin=${1:?usage: scripts/binary-size.sh BINARY [LIMIT_BYTES]}
limit=${2:-16000000}
[ -f "$bin" ] || { echo "binary-size: $bin: no such file (build it with cargo build --release)" >&2; exit 1; }
# The ELF header's machine field (bytes 18-19): 183 is AArch64, stripped by its own binutils.
strip=strip
if [ "$(od -An -tu2 -j18 -N2 "$bin" | tr -d ' ')" = 183 ]; then
  strip=aarch64-linux-gnu-strip
fi
stripped=$(mktemp)
trap 'rm -f "$stripped"' EXIT
"$strip" -o "$stripped" "$bin"
size=$(stat -c %s "$bin")
small=$(stat -c %s "$stripped")
mb() { awk -v b="$1" 'BEGIN { printf "%.2f MB", b / 1e6 }'; }
echo "$bin: $size bytes ($(mb "$size")) as built, $small bytes ($(mb "$small")) stripped; limit $limit bytes ($(mb "$limit"))"
if [ "$size" -gt "$limit" ]; then
  echo "binary-size: the binary as built is $((size - limit)) bytes over the limit" >&2
  exit 1
fi
