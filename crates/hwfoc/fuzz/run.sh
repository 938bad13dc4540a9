#!/usr/bin/env bash
# Fuzz every hwfoc target in turn, each for DURATION seconds (default 30).
#
#   crates/hwfoc/fuzz/run.sh [DURATION]
#
# Needs cargo-fuzz (installed here with `cargo install cargo-fuzz --locked` when missing: about
# a minute on a 2-core machine) and a nightly toolchain. Without nightly (a machine whose rustup
# has only stable, and no way to download another toolchain), the stable compiler is used with
# RUSTC_BOOTSTRAP=1, which unlocks the -Z flags cargo-fuzz passes; the build is the same.
#
# The corpus (fuzz/corpus/<target>) is kept between runs and seeded with real frames when empty.
# A crash stops that target, leaves its input in fuzz/artifacts/<target>/, and makes the script
# exit non-zero once every target has run.
set -euo pipefail

duration="${1:-30}"
case "$duration" in
'' | *[!0-9]*)
    echo "usage: $0 [DURATION_SECONDS]" >&2
    exit 2
    ;;
esac

fuzz_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$fuzz_dir/.." # crates/hwfoc: cargo fuzz looks for ./fuzz

if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "run.sh: installing cargo-fuzz" >&2
    start=$SECONDS
    cargo install cargo-fuzz --locked
    echo "run.sh: cargo-fuzz installed in $((SECONDS - start)) s" >&2
fi

if rustup run nightly rustc --version >/dev/null 2>&1; then
    toolchain=(+nightly)
else
    echo "run.sh: no nightly toolchain; using stable with RUSTC_BOOTSTRAP=1" >&2
    toolchain=(+stable)
    export RUSTC_BOOTSTRAP=1
fi

# Seeds: the first data frame of the XRotor capture, the device-information frame seen after
# idle frames, a lone sync byte and a fake header, as in PROTOCOL-NOTES.md.
data_frame='\x9b\x16\x01\x02\x05\xc2\x00\x00\x00\x00\x00\x00\x00\xf7\xff\xff\xff\xff\xce\xd1\x00\x00\x0d\x08'
info_text="$(printf '%-16s%-16s%-16s%-16s%-8s' '' XR_FOC_ESC HW577_KZ1_V1.1 XR-01.0.00 01040443)"
info_frame="\\x9b\\x4c\\x01\\x01${info_text}\\x34"
seed_stream="\\x00\\x9b\\x13${data_frame}${info_frame}\\x9b\\x16\\x01\\x02${data_frame}"

seed() { # seed TARGET PREFIX: write seeds unless the corpus already has inputs
    local dir="$fuzz_dir/corpus/$1"
    mkdir -p "$dir"
    if [ -z "$(ls -A "$dir")" ]; then
        printf "$2${data_frame}" >"$dir/seed-data-frame"
        printf "$2${info_frame}" >"$dir/seed-info-frame"
        printf "$2${seed_stream}" >"$dir/seed-stream"
    fi
}

failed=()
for target in $(cargo "${toolchain[@]}" fuzz list); do
    case "$target" in
    # stream: byte 0 picks one schedule byte, 0x07 = feed 7 bytes at a time.
    stream) seed "$target" '\x00\x07' ;;
    *) seed "$target" '' ;;
    esac
    echo "=== fuzz target $target: ${duration} s" >&2
    if ! cargo "${toolchain[@]}" fuzz run "$target" -- \
        -max_total_time="$duration" -print_final_stats=1; then
        failed+=("$target")
    fi
done

if [ "${#failed[@]}" -gt 0 ]; then
    echo "run.sh: FAILED: ${failed[*]} (inputs in $fuzz_dir/artifacts/)" >&2
    exit 1
fi
echo "run.sh: all fuzz targets ran ${duration} s without a failure" >&2
