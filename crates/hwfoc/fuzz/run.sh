#!/usr/bin/env bash
# Fuzz every hwfoc target in turn, each for DURATION seconds (default 30).
#
#   crates/hwfoc/fuzz/run.sh [DURATION]
#
# Ten targets: stream, bulk (HW-FOC), datalink, v3, v4, hw5, detect (every serial format at
# once), dronecan, canrecords (a CAN bus's record stream), c_header (c/hwfoc.h against the
# codec). The whole run takes 10 x DURATION seconds of fuzzing plus the build: at 30 s (CI), 300 s of fuzzing, and about 1.5 minutes to build the targets the first time on a 2-core
# machine (seconds once built).
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

# Seeds of the newer protocols, each made by hwfoc's encoders: V3 and V4 frames (no checksum:
# big-endian fields after a 9B, as `v3::Frame::encode` and `v4::DataFrame::encode` write them,
# which the targets check of every decoded frame), HW5 frames (CRC-16/MODBUS, from
# `hw5::TelemetryFrame::encode` and frames of the other kinds sealed by `wire::Checksum`) and
# DroneCAN frames (`dronecan::Message::frames`, the esc.Status transfer CRC included).
be() { # be WIDTH VALUE: VALUE as WIDTH big-endian bytes
    local i
    for ((i = $1 - 1; i >= 0; i--)); do printf '\\x%02x' $((($2 >> (8 * i)) & 255)); done
}
ramp() { # ramp N: the bytes 0, 1, ..., N-1
    local i
    for ((i = 0; i < $1; i++)); do printf '\\x%02x' $((i & 255)); done
}
v3_frame() { # v3_frame COUNTER THROTTLE PWM PERIOD_US
    printf '\\x9b%s%s%s%s' "$(be 3 "$1")" "$(be 2 "$2")" "$(be 2 "$3")" "$(be 2 "$4")"
}
v4_data() { # v4_data COUNTER THROTTLE ERPM: PWM = throttle, ADC fields 1365, 120, 2200, 2100
    printf '\\x9b%s%s%s%s%s%s%s%s' "$(be 3 "$1")" "$(be 2 "$2")" "$(be 2 "$2")" "$(be 3 "$3")" \
        "$(be 2 1365)" "$(be 2 120)" "$(be 2 2200)" "$(be 2 2100)"
}
# V3: noise, a chain of four frames (counters 100-103), a cut frame, a fake header, an ESC
# restart (counters 7-9, start-up placeholder period), two frames that do not chain.
v3_chain='\x00\x9b\x13'
for c in 0 1 2 3; do v3_chain+=$(v3_frame $((100 + c)) $((40 + 10 * c)) $((38 + 10 * c)) $((1500 - 100 * c))); done
v3_stream="${v3_chain}$(v3_frame 104 90 88 1100 | cut -c1-24)\\x9b\\x01\\x02"
for c in 7 8 9; do v3_stream+=$(v3_frame $c 0 0 35314); done
v3_stream+="$(v3_frame 16777215 255 255 0)$(v3_frame 0 255 255 1)"
# V4: idle (an info frame, full scale 1000, then a data frame with its B9 trailer, three times),
# then running (data frames back to back), a cut frame, a jump in the counter.
v4_info='\x9b\x9b\x03\xe8\x01\x08\x5b\x0b\x02\x01\x21\x21\xb9'
v4_slow=''
for c in 0 1 2; do v4_slow+="${v4_info}$(v4_data $c 0 0)\\xb9"; done
v4_stream=$v4_slow
for c in 3 4 5 6 7; do v4_stream+=$(v4_data $c $((250 + 50 * c)) $((9000 + 700 * c))); done
v4_stream+=$(v4_data 8 700 15000 | cut -c1-44)
for c in 20 21 22; do v4_stream+=$(v4_data $c 650 14000); done
# HW5: a telemetry frame (55 %, 4200 eRPM/10, 50.4 V, 35.7 A, 48/41/55 degC, BEC 8.4 V 1.2 A),
# Rotorflight's ping request, and the ESC's other kinds (payload 00 01 02 ..., then the CRC).
hw5_telemetry='\xfe\x01\x00\x03\x30\x5c\x17\x06\x00\x37\x00\x00\x00\x68\x10\xf8\x01\x65\x01\x30\x29\x37\x54\x0c\xff\xff\xff\xff\xff\xff\xce\xf6'
hw5_ping_request='\x01\xfd\x03\x03\x2c\x24\x00\x01\x60\x60'
hw5_ping="\\xfe\\x01\\x00\\x03\\x2c\\x24$(ramp 3)\\x98\\x0c"
hw5_reset="\\xfe\\x01\\x00\\x01\\x2b\\x02$(ramp 2)\\x8a\\x27"
hw5_write_error="\\xfe\\x01\\x00\\x02\\x35\\x38$(ramp 1)\\x07\\x68"
hw5_written="\\xfe\\x01\\x00\\x02\\x35\\x38$(ramp 50)\\x51\\xcf"
hw5_device_info="\\xfe\\x01\\x00\\x03\\x2c\\x25$(ramp 65)\\x93\\x62"
hw5_read="\\xfe\\x01\\x00\\x02\\x35\\x38$(ramp 97)\\xea\\x15"
hw5_stream="\\xfe\\x01${hw5_telemetry}${hw5_ping_request}${hw5_ping}${hw5_telemetry}"
hw5_others="${hw5_reset}${hw5_write_error}${hw5_written}${hw5_device_info}"
hw5_others+="$(printf '%s' "$hw5_telemetry" | cut -c1-80)${hw5_telemetry}"
# DroneCAN: records of the dronecan target (see fuzz_targets/dronecan.rs): HOW | length << 2,
# the id little-endian, the data.
can() { # can HOW ID BYTE...: a frame record (HOW 0: SocketCAN id, 1: extended)
    local how=$1 id=$2
    shift 2
    printf '\\x%02x' $((how | $# << 2)) $((id & 255)) $((id >> 8 & 255)) $((id >> 16 & 255)) \
        $((id >> 24 & 255)) "${@/#/0x}"
}
# StatusMsg1/2/3 of node 1, an esc.Status of node 2 (three frames), StatusMsg1 of node 2,
# NodeStatus of node 3; transfer ids 0-5, priority 16.
can_frames() { # can_frames HOW FLAGS
    can "$1" $((0x104E5201 | $2)) b0 04 2c 01 00 00 c0
    can "$1" $((0x104E5301 | $2)) f8 01 65 01 30 c1
    can "$1" $((0x104E5401 | $2)) 30 29 37 c2
    can "$1" $((0x10040A02 | $2)) 0f 71 07 00 00 00 4d 83
    can "$1" $((0x10040A02 | $2)) 52 70 50 04 5d 28 23 23
    can "$1" $((0x10040A02 | $2)) 1f 08 43
    can "$1" $((0x104E5202 | $2)) 14 05 36 01 00 00 c4
    can "$1" $((0x10015503 | $2)) 0c 00 00 00 00 00 00 c5
}
can_extended=$(can_frames 1 0)
# The same as SocketCAN ids (extended flag), then a remote, an error and a standard frame.
can_socketcan="$(can_frames 0 $((0x80000000)))$(can 0 $((0xC0000123)) 00 00 00 00)"
can_socketcan+="$(can 0 $((0x20000004)) 00 04 00 00 00 00 00 00)$(can 0 $((0x123)) 09)"
# One transfer of every known type made by the target's encoder (HOW 3): kind index, priority,
# source, destination, transfer id, then a payload of the type's longest length.
can_messages=''
k=0
for len in 6 5 3 3 7 14 7 2 2 1 0 3 3 1 1 4 4 1 1 0 1 3 5 1 7 1 7; do
    can_messages+=$(printf '\\x%02x\\x%02x\\x10\\x%02x\\x01\\x%02x' $((3 | len << 2)) $k $((10 + k)) $k)
    can_messages+=$(ramp "$len")
    k=$((k + 1))
done

# canrecords (see fuzz_targets/canrecords.rs): timed (byte 0 even); transfers made by the
# target's encoder (0xFD, kind, node, transfer id, length, payload): node 5's StatusMsg2,
# GetEscID answer [5, 3], StatusMsg1, node 9's StatusExtended and esc.Status (the kinds' longest
# payloads); then 16-byte SocketCAN records after a time step: node 5's StatusMsg3 twice,
# an error frame and a remote frame.
sock() { # sock ID BYTE...: a LINKTYPE_CAN_SOCKETCAN record, the id big-endian
    local id=$1 b
    shift
    printf '%s\\x%02x\\x00\\x00\\x00' "$(be 4 "$id")" $#
    for b in "$@" 00 00 00 00 00 00 00 00; do printf '\\x%02x' $((0x$b)); done | cut -c1-32
}
can_records='\x00'
k=0
for spec in "1 5 5" "3 5 2 5 3" "0 5 6" "5 9 7" "4 9 14"; do
    set -- $spec
    can_records+=$(printf '\\xfd\\x%02x\\x%02x\\x%02x\\x%02x' "$1" "$2" $k "$3")
    if [ $# -gt 3 ]; then
        for b in "${@:4}"; do can_records+=$(printf '\\x%02x' "$b"); done
    else
        can_records+=$(ramp "$3")
    fi
    k=$((k + 1))
done
can_records+="\\x14$(sock $((0x904E5405)) 30 29 37 c0)\\x01$(sock $((0x904E5405)) 30 29 37 c1)"
can_records+="\\x00$(sock $((0x20000004)) 00 04 00 00 00 00 00 00)\\x02$(sock $((0xC0000123)))"

seed_new() { # seed_new TARGET PREFIX NAME=SEED...: as seed, with the given seeds
    local dir="$fuzz_dir/corpus/$1" prefix=$2 name_seed
    shift 2
    mkdir -p "$dir"
    if [ -z "$(ls -A "$dir")" ]; then
        for name_seed in "$@"; do
            printf "${prefix}${name_seed#*=}" >"$dir/seed-${name_seed%%=*}"
        done
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
    # v3, v4, hw5: the same schedule layout as stream.
    v3) seed_new "$target" '\x00\x07' "v3-chain=$v3_chain" "v3-stream=$v3_stream" ;;
    v4) seed_new "$target" '\x00\x07' "v4-idle=$v4_slow" "v4-stream=$v4_stream" ;;
    hw5) seed_new "$target" '\x00\x07' "hw5-stream=$hw5_stream" "hw5-others=$hw5_others" \
        "hw5-parameters-read=$hw5_read" "hw5-device-info=$hw5_device_info" ;;
    # detect: the same schedule layout; every format's seeds, and streams that change format.
    detect) seed_new "$target" '\x00\x07' "v3-then-v4=$v3_stream$v4_stream" \
        "v4-then-hwfoc=$v4_slow$seed_stream" "hw5-then-v3=$hw5_stream$v3_chain" \
        "datalink-then-hw5=$datalink_stream$hw5_others" ;;
    # dronecan: records of CAN frames and of transfers to encode (no schedule).
    dronecan) seed_new "$target" '' "can-extended=$can_extended" \
        "can-socketcan=$can_socketcan" "can-messages=$can_messages" ;;
    # canrecords: its own layout (no schedule).
    canrecords) seed_new "$target" '' "can-records=$can_records" ;;
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
