#!/bin/sh
# m7-feature-cost.sh [LIBCCD_SRC]: what each vessel feature costs on the Cortex-M7 image
# (issue 18: "say what each feature costs there"). Builds the bare-metal image once as shipped
# (build/cortex-m7) and once per compile-time switch of config/sc_config.h turned off
# (build/m7-cost-<name>, -DSWITCH=0 added to the toolchain's MCU flags), and prints a Markdown
# table of .text (flash), .data and .bss (RAM) and the differences to the shipped image, plus
# the sizes of the features' structures on the target (arm-none-eabi-gcc sizeof, MCU limits).
# Needs arm-none-eabi-gcc (tools/install-deps.sh) and the libccd source (tools/fetch-libccd-
# source.sh; or give its folder). Builds with -j2; about 1 min per variant.
set -eu
ROOT=$(cd "$(dirname "$0")/.." && pwd)
CCD=${1:-$ROOT/third_party/libccd-src}
cd "$ROOT"
ELF=platform/baremetal/sonocomp-m7.elf

build() { # name, extra C flags
    dir=build/m7-cost-$1
    [ "$1" = shipped ] && dir=build/cortex-m7
    if [ "$1" = shipped ]; then
        cmake --preset cortex-m7 -DSC_LIBCCD_SOURCE_DIR="$CCD" > /dev/null
    else
        # the toolchain's flags (CMAKE_C_FLAGS given replaces its _INIT) and the switch
        base=$(sed -n 's/^CMAKE_C_FLAGS:STRING=//p' build/cortex-m7/CMakeCache.txt)
        rm -rf "$dir"
        cmake --preset cortex-m7 -B "$dir" -DSC_LIBCCD_SOURCE_DIR="$CCD" \
            -DCMAKE_C_FLAGS="$base $2" > /dev/null
    fi
    if ! cmake --build "$dir" -j2 > "$dir.log" 2>&1; then
        echo "build of $1 failed: $dir.log" >&2
        exit 1
    fi
    arm-none-eabi-size -A "$dir/$ELF" | awk -v n="$1" '
        $1 == ".text" || $1 ~ /^\.rodata/ || $1 == ".isr_vector" || $1 == ".ARM.exidx" { t += $2 }
        $1 == ".data" { d += $2 } $1 == ".bss" { b += $2 }
        END { printf "%s %d %d %d\n", n, t, d, b }'
}

OUT=$(mktemp)
trap 'rm -f "$OUT"' EXIT
{
    build shipped ""
    build no-doppler "-DSC_ENABLE_DOPPLER=0"
    build no-needle "-DSC_ENABLE_NEEDLE=0"
    build no-lumen "-DSC_PHYS_LUMEN=0"
    build none "-DSC_ENABLE_DOPPLER=0 -DSC_ENABLE_NEEDLE=0 -DSC_PHYS_LUMEN=0"
} > "$OUT"

echo "| image | flash: .text+.rodata (B) | .data (B) | .bss (B) | RAM saved vs shipped (B) | flash saved (B) |"
echo "|---|---:|---:|---:|---:|---:|"
awk 'NR == 1 { t0 = $2; r0 = $3 + $4 }
     { printf "| %s | %d | %d | %d | %d | %d |\n", $1, $2, $3, $4, r0 - ($3 + $4), t0 - $2 }' "$OUT"

# the structures' sizes on the target, with the MCU's limits
FLAGS=$(sed -n 's/^set(SC_MCU_LIMITS "\(.*\)")$/\1/p' cmake/toolchain-cortex-m7.cmake)
SRC=$(mktemp --suffix=.c)
NAMES="sc_engine sc_tissue sc_lumen sc_lumen_drive sc_doppler sc_needle sc_needle_rx sc_assess"
{
    echo '#include "sc_engine.h"'
    printf 'const unsigned sc_sizes[] = {'
    for n in $NAMES; do printf 'sizeof(%s), ' "$n"; done
    echo '};'
} > "$SRC"
INC=""
for d in core core/base core/link core/physics core/imaging core/case hal config; do
    INC="$INC -I$d"
done
OBJ=$(mktemp --suffix=.o)
BIN=$(mktemp)
# shellcheck disable=SC2086
if arm-none-eabi-gcc -std=c11 -mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb $FLAGS \
        $INC -I"$CCD/src" -Ibuild/cortex-m7/third_party/libccd/include -c "$SRC" -o "$OBJ" &&
    arm-none-eabi-objcopy -O binary -j .rodata "$OBJ" "$BIN"; then
    echo
    echo "| structure (Cortex-M7, MCU limits, sizeof) | bytes |"
    echo "|---|---:|"
    # shellcheck disable=SC2086
    set -- $NAMES
    for v in $(od -An -v -t u4 "$BIN"); do
        echo "| $1 | $v |"
        shift
        [ $# -gt 0 ] || break
    done
else
    echo "(sizeof probe did not compile)"
fi
rm -f "$SRC" "$OBJ" "$BIN"
