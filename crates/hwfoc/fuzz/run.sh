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
# idle frames, a lone sync byte and a fake header, as in docs/PROTOCOL-NOTES.md.
data_frame='\x9b\x16\x01\x02\x05\xc2\x00\x00\x00\x00\x00\x00\x00\xf7\xff\xff\xff\xff\xce\xd1\x00\x00\x0d\x08'
info_text="$(printf '%-16s%-16s%-16s%-16s%-8s' '' XR_FOC_ESC HW577_KZ1_V1.1 XR-01.0.00 01040443)"
info_frame="\\x9b\\x4c\\x01\\x01${info_text}\\x34"
seed_stream="\\x00\\x9b\\x13${data_frame}${info_frame}\\x9b\\x16\\x01\\x02${data_frame}"

# DataLink V2 seeds: a hub frame whose slot 0 holds that data frame's payload and whose other
# slots are empty, with length byte 0x9E (counter 1) and 0xA0 (counter 2); CRC-16/XMODEM from
# Python's binascii.crc_hqx(frame[:158], 0), as pinned in tests/datalink.rs.
zero18='\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
dl_records='\x00\x05\xc2\x00\x00\x00\x00\x00\x00\x00\xf7\xff\xff\xff\xff\xce\xd1\x00\x00'
for ch in 1 2 3 4 5 6 7; do dl_records+="\\x0${ch}${zero18}"; done
datalink_frame="\\x9b\\x9e\\x01\\x02\\x00\\x01${dl_records}\\x61\\x34"
datalink_frame_a0="\\x9b\\xa0\\x01\\x02\\x00\\x02${dl_records}\\xc9\\x15"
datalink_stream="\\x00\\x9b\\x13\\x9b\\x9e\\x01\\x02${datalink_frame}\\x9b${datalink_frame_a0}"

seed_datalink() { # seed_datalink TARGET PREFIX: as seed, with DataLink frames
    local dir="$fuzz_dir/corpus/$1"
    mkdir -p "$dir"
    if [ -z "$(ls -A "$dir")" ]; then
        printf "$2${datalink_frame}" >"$dir/seed-datalink-frame"
        printf "$2${datalink_frame_a0}" >"$dir/seed-datalink-frame-a0"
        printf "$2${datalink_stream}" >"$dir/seed-datalink-stream"
    fi
}

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
    # datalink: the same schedule layout as stream.
    datalink) seed_datalink "$target" '\x00\x07' ;;
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
