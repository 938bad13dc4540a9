#!/usr/bin/env bash
# The C checks of hwfoc.h (CI's `c-header` step): the header builds without a warning under
# -std=c99 -Wall -Wextra -Wpedantic -Wconversion -Werror with gcc and clang, as C++11 with g++
# and clang++, with every HWFOC_NO_* format left out in turn; tests/test.c and the example run
# under AddressSanitizer and UndefinedBehaviorSanitizer. Needs gcc, g++, clang, clang++.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
strict=(-Wall -Wextra -Wpedantic -Wconversion -Wshadow -Wcast-qual -Werror)
unit="$out/unit.c"
printf '#define HWFOC_IMPLEMENTATION\n#define HWFOC_FLOAT\n#include "hwfoc.h"\n' >"$unit"

for cc in gcc clang; do
  command -v "$cc" >/dev/null || { echo "c/test.sh: $cc not found" >&2; exit 1; }
done
selections=("" "-DHWFOC_NO_FOC" "-DHWFOC_NO_DATALINK" "-DHWFOC_NO_V3" "-DHWFOC_NO_V4" "-DHWFOC_NO_HW5"
  "-DHWFOC_NO_CAN" "-DHWFOC_NO_FOC -DHWFOC_NO_DATALINK" "-DHWFOC_NO_V3 -DHWFOC_NO_V4 -DHWFOC_NO_HW5"
  "-DHWFOC_NO_FOC -DHWFOC_NO_DATALINK -DHWFOC_NO_V3 -DHWFOC_NO_V4 -DHWFOC_NO_HW5")
for sel in "${selections[@]}"; do
  # shellcheck disable=SC2086
  {
    gcc -std=c99 "${strict[@]}" $sel -I"$here" -c "$unit" -o "$out/gcc.o"
    clang -std=c99 "${strict[@]}" $sel -I"$here" -c "$unit" -o "$out/clang.o"
    g++ -std=c++11 "${strict[@]}" $sel -I"$here" -x c++ -c "$unit" -o "$out/gxx.o"
    clang++ -std=c++11 "${strict[@]}" $sel -I"$here" -x c++ -c "$unit" -o "$out/clangxx.o"
  }
done
echo "c/test.sh: strict builds clean (gcc, clang, g++, clang++; ${#selections[@]} selections)"

san=(-std=c99 -g -O1 -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
gcc "${san[@]}" "${strict[@]}" "$here/tests/test.c" -o "$out/test" -lm
"$out/test" "$here/tests/vectors.txt"
gcc "${san[@]}" -D_POSIX_C_SOURCE=200809L "${strict[@]}" -I"$here" "$here/examples/serial.c" -o "$out/serial"
"$out/serial" --self-test
echo "c/test.sh: ok"
