#!/usr/bin/env bash
# Instructions per byte of the C HW-FOC decoder (docs/PERFORMANCE.md, "The C header"): ipb.c
# built with gcc -O2 (default and HWFOC_NO_FOC_INFO), run under cachegrind on a clean and a
# noisy 2 MiB stream, fed in 64 KiB chunks and a byte at a time; the count of a run that only
# reads the file is subtracted. Beside them the Rust codec's decoder on the same streams
# (crates/hwfoc-c-tests/examples/ipb.rs, built here with cargo --release). Needs gcc, valgrind
# and cargo.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
command -v valgrind >/dev/null || { echo "c/bench/ipb.sh: valgrind not found (apt-get install valgrind)" >&2; exit 1; }
irefs() { valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file=/dev/null "$@" 2>&1 >/dev/null |
  awk '/I *refs:/ { gsub(",", "", $NF); print $NF }'; }
cargo build --quiet --release --manifest-path "$here/../../Cargo.toml" -p hwfoc-c-tests --example ipb
rust=$(cd "$here/../.." && cargo metadata --format-version 1 --no-deps |
  python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')/release/examples/ipb
gcc -O2 -std=c11 -I"$here/.." "$here/ipb.c" -o "$out/ipb"
gcc -O2 -std=c11 -DHWFOC_NO_FOC_INFO -I"$here/.." "$here/ipb.c" -o "$out/ipb-data-only"
"$out/ipb" write "$out"  # the streams
echo "| build | stream | feed, 64 KiB chunks | push, byte at a time |"
echo "|---|---|---:|---:|"
cp "$rust" "$out/rust"
for bin in rust ipb ipb-data-only; do
  for s in clean noisy; do
    f="$out/$s.bin" bytes=$(stat -c %s "$out/$s.bin")
    base=$(irefs "$out/$bin" none "$f")
    feed=$(irefs "$out/$bin" feed "$f") push=$(irefs "$out/$bin" push "$f")
    awk -v b="$bin" -v s="$s" -v n="$bytes" -v z="$base" -v f="$feed" -v p="$push" \
      'BEGIN { printf "| %s | %s | %.1f | %.1f |\n", b, s, (f - z) / n, (p - z) / n }'
  done
done
