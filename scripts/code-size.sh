#!/usr/bin/env bash
# Release code size of the hwfoc streaming decoders on a Cortex-M4F (thumbv7em-none-eabihf).
#
# Builds crates/hwfoc/size-probe, a no_std staticlib (opt-level "s", fat LTO, one codegen unit,
# panic = abort), three times: with the entry point `hwfoc_probe_push` only (Decoder::push, a few
# raw fields of the last data frame), then with `hwfoc_probe_push_units` as well (feature `units`:
# voltage, currents and RPM under caller settings, temperatures from the ADC table), then with
# `hwfoc_probe_datalink_push` alone (feature `datalink` without the default `esc`:
# datalink::Decoder::push, the counter and a few raw fields of each ESC of the last hub frame),
# then each of the newer decoders alone the same way: `hwfoc_probe_v3_push` (feature `v3`),
# `hwfoc_probe_v4_push` (`v4`), `hwfoc_probe_hw5_push` (`hw5`): Decoder::push and a few raw
# fields of the last frame; `hwfoc_probe_dronecan_push` (`dronecan`): the DroneCAN receive path,
# Receiver::push of one CAN frame (reassembly, transfer CRC, decoding of every known type,
# per-node statistics) and a few fields of a completed ESC message.
#
# After LTO the probe's own object in the archive holds exactly the code those entry points reach.
# Counted, from that object: its .text* sections (entry points, hwfoc code, core's panic stubs;
# literal pools are inside .text), its .rodata* sections (the 1 KiB f32 temperature table) and its
# .data*/.bss* sections (static RAM; the decoder state itself is the caller's, reported apart).
# Not counted: the compiler-builtins memory helpers it calls (memcpy, memclr: listed, as any
# firmware links them anyway) and .ARM.exidx (unwind index entries, 8 bytes per function, which
# embedded linker scripts usually discard).
#
# Tools: llvm-size/-nm/-ar from the rustup component llvm-tools (added if missing), else the same
# on PATH, else arm-none-eabi-size/-nm/-ar (binutils-arm-none-eabi, installed with apt-get when
# running as root). Figures depend on the compiler version, printed first.
set -euo pipefail

target=thumbv7em-none-eabihf
probe=$(cd "$(dirname "${BASH_SOURCE[0]}")/../crates/hwfoc/size-probe" && pwd)
cd "$probe"

if command -v rustup >/dev/null && ! rustup target list --installed | grep -qx "$target"; then
    rustup target add "$target" >&2
fi

# Size and symbol tools that read ARM ELF objects.
host=$(rustc -vV | sed -n 's/^host: //p')
llvm_bin=$(rustc --print sysroot)/lib/rustlib/$host/bin
if [[ ! -x $llvm_bin/llvm-size ]] && command -v rustup >/dev/null; then
    rustup component add llvm-tools >&2 || echo "code-size: could not add llvm-tools" >&2
fi
if [[ -x $llvm_bin/llvm-size && -x $llvm_bin/llvm-nm && -x $llvm_bin/llvm-ar ]]; then
    size=$llvm_bin/llvm-size nm=$llvm_bin/llvm-nm
elif command -v llvm-size >/dev/null && command -v llvm-nm >/dev/null \
    && command -v llvm-ar >/dev/null; then
    size=llvm-size nm=llvm-nm
else
    if ! command -v arm-none-eabi-size >/dev/null && [[ $(id -u) == 0 ]] \
        && command -v apt-get >/dev/null; then
        apt-get update -qq >&2
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq binutils-arm-none-eabi >&2
    fi
    size=arm-none-eabi-size nm=arm-none-eabi-nm
    command -v "$size" >/dev/null || {
        echo "code-size: need llvm-size (rustup component add llvm-tools) or arm-none-eabi-size" >&2
        exit 1
    }
fi

lib=$probe/target/$target/release/libhwfoc_size_probe.a
ar=${size%size}ar # llvm-ar or arm-none-eabi-ar, next to the size tool
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# Builds the probe with the given cargo arguments, extracts its own object from the archive to
# $tmp/probe.o (the other members are compiler-builtins, some holding bitcode that older tools
# cannot read) and prints "<label>: sizes" for it.
measure() {
    local label=$1
    shift
    cargo build --release --target "$target" --target-dir target "$@" >&2
    local member
    member=$("$ar" t "$lib" | grep '^hwfoc_size_probe-' || true)
    if [[ -z $member || $member == *$'\n'* ]]; then
        echo "code-size: expected one hwfoc_size_probe object in $lib" >&2
        exit 1
    fi
    (cd "$tmp" && "$ar" x "$lib" "$member" && mv "$member" probe.o)
    "$nm" -u "$tmp/probe.o" | awk '{ print $NF }' >>"$tmp/helpers"
    # `size -A`: one "<section> <size> <addr>" line per section.
    "$size" -A "$tmp/probe.o" | awk -v label="$label" '
        $1 ~ /^\.text/ { text += $2 }
        $1 ~ /^\.rodata/ { ro += $2 }
        $1 ~ /^\.(data|bss)/ { ram += $2 }
        END {
            if (text == 0) { print "code-size: no .text in the probe object" > "/dev/stderr"; exit 1 }
            printf "%s: %d bytes .text, %d bytes .rodata, %d bytes .data/.bss\n", label, text, ro, ram
        }'
}

echo "hwfoc release code size on $target ($(rustc -V); opt-level \"s\", LTO, panic = abort)"
measure "decoder (push + frame fields)"
measure "decoder + units (conversions, ADC table)" --features units
measure "DataLink decoder alone (push + frame fields)" --no-default-features --features datalink
measure "V3 decoder alone (push + frame fields)" --no-default-features --features v3
measure "V4 decoder alone (push + frame fields)" --no-default-features --features v4
measure "HW5 decoder alone (push + telemetry fields)" --no-default-features --features hw5
measure "DroneCAN receiver alone (push a CAN frame + message fields)" \
    --no-default-features --features dronecan

# The build asserts size_of::<Decoder>() == DECODER_STATE_BYTES for the target, and the same of
# the DataLink, V3, V4 and HW5 decoders and the DroneCAN receiver.
state=$(sed -n 's/^pub const DECODER_STATE_BYTES: usize = \([0-9]*\);.*/\1/p' src/lib.rs)
echo "decoder state: ${state:?} bytes (size_of::<Decoder>(), owned by the caller)"
dl_state=$(sed -n 's/^pub const DATALINK_DECODER_STATE_BYTES: usize = \([0-9]*\);.*/\1/p' src/lib.rs)
echo "DataLink decoder state: ${dl_state:?} bytes (size_of::<datalink::Decoder>(), owned by the caller)"
state_of() { # state_of CONST: the value of `pub const CONST: usize = N;` in the probe
    sed -n "s/^pub const $1: usize = \([0-9]*\);.*/\1/p" src/lib.rs
}
v3_state=$(state_of V3_DECODER_STATE_BYTES)
echo "V3 decoder state: ${v3_state:?} bytes (size_of::<v3::Decoder>(), owned by the caller)"
v4_state=$(state_of V4_DECODER_STATE_BYTES)
echo "V4 decoder state: ${v4_state:?} bytes (size_of::<v4::Decoder>(), owned by the caller)"
hw5_state=$(state_of HW5_DECODER_STATE_BYTES)
echo "HW5 decoder state: ${hw5_state:?} bytes (size_of::<hw5::Decoder>(), owned by the caller)"
can_state=$(state_of DRONECAN_RECEIVER_STATE_BYTES)
echo "DroneCAN receiver state: ${can_state:?} bytes (size_of::<dronecan::Receiver>(): 128 slots, one per node id," \
    "statistics of 128 node ids; owned by the caller)"

# Symbols the probe objects take from outside (every build).
helpers=$(sort -u "$tmp/helpers" | tr '\n' ' ')
echo "not counted: ${helpers:-nothing }(compiler-builtins helpers), .ARM.exidx unwind index"
