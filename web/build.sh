#!/bin/sh
# Builds the browser app into web/dist/, the folder `hwfoc web` serves and any static host can:
# the WebAssembly crate (crates/hwfoc-web, the `web` profile), its JavaScript glue (wasm-bindgen's
# library at the crate's version) and the page's files (crates/hwfoc-web-build does it all).
# Needs only Rust and its wasm32-unknown-unknown target (rust-toolchain.toml names it).
set -eu
web=$(cd "$(dirname "$0")" && pwd)
cargo run --quiet --manifest-path "$web/../Cargo.toml" -p hwfoc-web-build -- "$web/dist"

size=0
for f in $(find "$web/dist" -type f); do size=$((size + $(gzip -9c "$f" | wc -c))); done
echo "web/dist: $size bytes gzipped (budget 1048576)"
[ "$size" -le 1048576 ] || { echo "web/build.sh: the page is over its 1 MB budget" >&2; exit 1; }
