#!/usr/bin/env bash
# (Re)writes the checked-in seed corpora tests/fuzz/corpus/<name>/seed-NN from each fuzz
# target's own seeds (sc_fuzz_seed in tests/fuzz/fuzz_<name>.c), with its smoke driver:
#   tools/fuzz-seeds.sh [BUILD_DIR]     (default build/fuzz, else build/dev)
# Other files in a corpus folder (inputs libFuzzer found worth keeping) are left alone. Run it
# after changing a target's seeds and commit the result.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-}
if [ -z "$build" ]; then
    build=$top/build/fuzz
    [ -d "$build/tests" ] || build=$top/build/dev
fi
n=0
for src in "$top"/tests/fuzz/fuzz_*.c; do
    target=$(basename "$src" .c)
    name=${target#fuzz_}
    bin=$build/tests/${target}_smoke
    if [ ! -x "$bin" ]; then
        echo "fuzz-seeds: $bin missing (build it: cmake --build --preset fuzz)" >&2
        exit 1
    fi
    dir=$top/tests/fuzz/corpus/$name
    mkdir -p "$dir"
    rm -f "$dir"/seed-[0-9][0-9]
    "$bin" --write-seeds "$dir"
    n=$((n + 1))
done
echo "fuzz-seeds: $n targets"
