#!/bin/sh
# Builds the browser app into web/dist/: the WebAssembly crate (crates/hwfoc-web) in release,
# its JavaScript glue (wasm-bindgen, the version Cargo.lock pins), and the page's files.
# Usage: web/build.sh   (from anywhere; needs the wasm32-unknown-unknown target and
# wasm-bindgen-cli at the version of the wasm-bindgen crate in Cargo.lock)
set -eu
web=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$web")
target=${CARGO_TARGET_DIR:-$root/target}

cargo build --manifest-path "$root/Cargo.toml" -p hwfoc-web --profile web \
  --target wasm32-unknown-unknown

want=$(awk '/^name = "wasm-bindgen"$/ { getline; sub(/^version = "/, ""); sub(/"$/, ""); print; exit }' \
  "$root/Cargo.lock")
have=$(wasm-bindgen --version 2>/dev/null | awk '{ print $2 }' || true)
if [ "$have" != "$want" ]; then
  echo "web/build.sh: wasm-bindgen $want is needed (found '${have:-none}'):" \
    "cargo install wasm-bindgen-cli --locked --version =$want" >&2
  exit 1
fi

rm -rf "$web/pkg"
wasm-bindgen --target web --no-typescript --out-dir "$web/pkg" \
  "$target/wasm32-unknown-unknown/web/hwfoc_web.wasm"

rm -rf "$web/dist"
mkdir -p "$web/dist"
cp -RL "$web/index.html" "$web/style.css" "$web/src" "$web/pkg" "$web/dist/"
[ -f "$web/sw.js" ] && cp "$web/sw.js" "$web/dist/"

size=0
for f in $(find "$web/dist" -type f); do size=$((size + $(gzip -9c "$f" | wc -c))); done
echo "web/dist: $(cd "$web/dist" && find . -type f | wc -l) files, $size bytes gzipped"
