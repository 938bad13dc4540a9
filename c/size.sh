#!/usr/bin/env bash
# Code size of hwfoc.h on a Cortex-M4 (CI's `c-size` step): arm-none-eabi-gcc -Os -mcpu=cortex-m4
# -mthumb, each configuration linked with --gc-sections from an entry that calls what a board
# calls (a decoder: init, push, feed, flush, line_silent), its code and constant data summed
# from the symbols of the header (libc's memcpy/memset/memmove not counted: every firmware has
# them). Prints the table and fails past the issue's budgets:
#   HW-FOC decoder <= 1024 B of code, and <= 64 B of state (the whole hwfoc_foc_decoder, its
#   candidate buffer included) in the build the state budget applies to: HWFOC_NO_FOC_INFO
#   (data frames only; the default build holds a 77-byte info frame, 136 B in all),
#   DataLink decoder <= 1536 B, all serial decoders together <= 4096 B, the DroneCAN payload
#   codec <= 2048 B.
# Needs Debian's gcc-arm-none-eabi and libnewlib-arm-none-eabi.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cc=arm-none-eabi-gcc
command -v "$cc" >/dev/null || { echo "c/size.sh: $cc not found (apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi)" >&2; exit 1; }
flags=(-std=c99 -Os -mcpu=cortex-m4 -mthumb -ffunction-sections -fdata-sections -Wall -Wextra -Werror
  -nostartfiles --specs=nano.specs -Wl,--gc-sections -Wl,-e,size_entry -I"$here")

# calls PFX: the decoder's calls, as a board makes them.
calls() {
  local p=$1 frame=$2
  cat <<C
static void on_$p(void *ctx, const $frame *f) { *(volatile const void **)ctx = f; }
static hwfoc_${p}_decoder dec_$p;
static void use_$p(const uint8_t *b, size_t n, void *ctx) {
    hwfoc_${p}_init(&dec_$p);
    hwfoc_${p}_push(&dec_$p, b[0], on_$p, ctx);
    hwfoc_${p}_feed(&dec_$p, b, n, on_$p, ctx);
    hwfoc_${p}_line_silent(&dec_$p, (uint32_t)n, on_$p, ctx);
    hwfoc_${p}_flush(&dec_$p, on_$p, ctx);
}
C
}

# measure NAME "DEFINES" "PREFIXES": the bytes of the header's symbols in the linked image.
measure() {
  local name=$1 defines=$2 prefixes=$3 src="$out/$1.c" p
  {
    printf '#define HWFOC_IMPLEMENTATION\n'
    for d in $defines; do printf '#define %s\n' "$d"; done
    printf '#include "hwfoc.h"\n'
    for p in $prefixes; do
      case $p in
        foc) calls foc hwfoc_foc_frame ;; dl) calls dl hwfoc_dl_frame ;; v3) calls v3 hwfoc_v3_frame ;;
        v4) calls v4 hwfoc_v4_frame ;; hw5) calls hw5 hwfoc_hw5_frame ;;
        can) printf 'static uint8_t can_out[HWFOC_CAN_MAX_PAYLOAD];\nstatic void use_can(const uint8_t *b, size_t n, void *ctx) {\n    int32_t f[HWFOC_CAN_MAX_FIELDS];\n    hwfoc_can_unpack((hwfoc_can_type)b[0], b, n, f);\n    *(volatile size_t *)ctx = hwfoc_can_pack((hwfoc_can_type)b[1], f, can_out);\n}\n' ;;
      esac
    done
    printf 'volatile const uint8_t *size_in; volatile size_t size_n; const void *volatile size_out;\n'
    printf 'void size_entry(void) {\n'
    for p in $prefixes; do printf '    use_%s((const uint8_t *)size_in, size_n, (void *)&size_out);\n' "$p"; done
    printf '}\n'
  } >"$src"
  "$cc" "${flags[@]}" "$src" -o "$out/$name.elf" -lc
  # Code and constants of the header: every text or read-only symbol but the harness's and libc's.
  arm-none-eabi-nm -S -t d --size-sort "$out/$name.elf" | awk '
    $3 ~ /^[tTrR]$/ && $4 !~ /^(size_entry|use_|on_|mem(cpy|set|move))/ { sum += $2 }
    END { print sum + 0 }'
}

state() { # TYPE [DEFINE]: the size of a type, from a global array of that size
  printf '#define HWFOC_IMPLEMENTATION\n%s\n#include "hwfoc.h"\nchar state[sizeof(%s)];\n' "${2:+#define $2}" "$1" >"$out/state.c"
  "$cc" -std=c99 -Os -mcpu=cortex-m4 -mthumb -I"$here" -c "$out/state.c" -o "$out/state.o"
  arm-none-eabi-nm -S -t d "$out/state.o" | awk '$4 == "state" { print $2 + 0 }'
}

foc=$(measure foc "HWFOC_NO_DATALINK HWFOC_NO_V3 HWFOC_NO_V4 HWFOC_NO_HW5 HWFOC_NO_CAN" foc)
dl=$(measure dl "HWFOC_NO_FOC HWFOC_NO_V3 HWFOC_NO_V4 HWFOC_NO_HW5 HWFOC_NO_CAN" dl)
v3=$(measure v3 "HWFOC_NO_FOC HWFOC_NO_DATALINK HWFOC_NO_V4 HWFOC_NO_HW5 HWFOC_NO_CAN" v3)
v4=$(measure v4 "HWFOC_NO_FOC HWFOC_NO_DATALINK HWFOC_NO_V3 HWFOC_NO_HW5 HWFOC_NO_CAN" v4)
hw5=$(measure hw5 "HWFOC_NO_FOC HWFOC_NO_DATALINK HWFOC_NO_V3 HWFOC_NO_V4 HWFOC_NO_CAN" hw5)
all=$(measure all "HWFOC_NO_CAN" "foc dl v3 v4 hw5")
can=$(measure can "HWFOC_NO_FOC HWFOC_NO_DATALINK HWFOC_NO_V3 HWFOC_NO_V4 HWFOC_NO_HW5" can)
foc_data_only=$(measure foc_data_only "HWFOC_NO_FOC_INFO HWFOC_NO_DATALINK HWFOC_NO_V3 HWFOC_NO_V4 HWFOC_NO_HW5 HWFOC_NO_CAN" foc)
foc_state=$(state hwfoc_foc_decoder)
foc_data_only_state=$(state hwfoc_foc_decoder HWFOC_NO_FOC_INFO)

status=0
row() { # name bytes budget
  local verdict=ok
  if [ "$3" != - ] && [ "$2" -gt "$3" ]; then verdict="OVER BUDGET"; status=1; fi
  printf '| %-40s | %6s | %6s | %s |\n' "$1" "$2" "$3" "$verdict"
}
echo "hwfoc.h on a Cortex-M4 ($("$cc" -dumpversion), -Os -mthumb), bytes:"
echo "| what | bytes | budget | |"
echo "|---|---:|---:|---|"
row "HW-FOC decoder, code" "$foc" 1024
row "HW-FOC decoder, state (77-byte buffer)" "$foc_state" -
row "HW-FOC data only (HWFOC_NO_FOC_INFO), code" "$foc_data_only" 1024
row "HW-FOC data only (HWFOC_NO_FOC_INFO), state" "$foc_data_only_state" 64
row "DataLink V2 decoder, code" "$dl" 1536
row "V3 decoder, code" "$v3" -
row "V4 decoder, code" "$v4" -
row "HW5 decoder, code" "$hw5" -
row "all five serial decoders, code" "$all" 4096
row "DroneCAN payloads (pack, unpack), code" "$can" 2048
for t in hwfoc_dl_decoder hwfoc_v3_decoder hwfoc_v4_decoder hwfoc_hw5_decoder; do
  row "$t, state" "$(state "$t")" -
done
exit $status
