#!/usr/bin/env bash
# The CAN traffic soak (issue 14): the whole engine on the host simulator under random valid
# and invalid CAN traffic (tests/soak/sc_soak_frames.c: poses, random frames, protocol ids
# with random and with E2E-valid random content, stale replays, a bus that drops, corrupts,
# duplicates and reorders), its invariants checked after every engine frame, and a state hash
# checkpoint every 1000 engine frames. Runs it twice with the same seed and fails unless both
# runs pass and print the same checkpoints (the engine is deterministic: any difference is
# uninitialised state, time or address dependence).
#   tools/soak-frames.sh [--seed S] [--bin PROGRAM] [--out DIR] [CAN_FRAMES]
# CAN_FRAMES defaults to 1,000,000 (about 87,000 engine frames; 2 x 1 min with the release
# preset, which is built when PROGRAM is not given). ctest runs a shorter count with the dev
# preset's sanitizers (tests/soak.cmake). Checkpoints in DIR (default build/soak).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
seed=1 bin= out= count=1000000
while [ $# -gt 0 ]; do
    case "$1" in
    --seed) seed=$2; shift 2 ;;
    --bin) bin=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -h | --help) sed -n '2,12p' "$0"; exit 0 ;;
    *[!0-9]* | '') echo "soak-frames: unexpected argument '$1'" >&2; exit 2 ;;
    *) count=$1; shift ;;
    esac
done
if [ -z "$bin" ]; then
    (cd "$top" && cmake --preset release >/dev/null &&
        cmake --build --preset release --target sc_soak_frames -j"$(nproc)" >/dev/null)
    bin=$top/build/release/tests/sc_soak_frames
fi
out=${out:-$top/build/soak}
mkdir -p "$out"
start=$(date +%s)
for run in 1 2; do
    if ! "$bin" --can-frames "$count" --seed "$seed" --out "$out/run$run.txt" 2>"$out/run$run.err"; then
        cat "$out/run$run.err" >&2
        echo "soak-frames: run $run FAILED (seed $seed, $count CAN frames)" >&2
        exit 1
    fi
done
cat "$out/run1.err"
if ! cmp -s "$out/run1.txt" "$out/run2.txt"; then
    diff "$out/run1.txt" "$out/run2.txt" | head -5 >&2
    echo "soak-frames: the two runs differ (checkpoints in $out)" >&2
    exit 1
fi
echo "soak-frames: seed $seed, $count CAN frames, $(($(wc -l <"$out/run1.txt") - 1)) checkpoints" \
    "identical in both runs, last: $(tail -1 "$out/run1.txt"); $(($(date +%s) - start)) s"
