#!/usr/bin/env bash
# CI's fuzzing stage: builds the fuzz preset (clang, libFuzzer, ASan + UBSan, every library
# instrumented) and runs every target of tests/fuzz for FUZZ_SECONDS (default 60) each, two
# at a time (FUZZ_JOBS, default 2), from the checked-in corpora. Prints a table per target
# (executions, exec/s, coverage edges, features, corpus, findings) and fails on any finding
# (crash, leak, timeout, out-of-memory, a broken invariant): see tools/fuzz.sh for what to do
# with one. Wall time: the build (about 3 min from scratch on 2 cores) plus
# targets x FUZZ_SECONDS / FUZZ_JOBS (15 targets: 7.5 min).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"
secs=${FUZZ_SECONDS:-60}
jobs=${FUZZ_JOBS:-2}
start=$(date +%s)
tools/install-deps.sh fuzz
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j"$(nproc)"
built=$(date +%s)
targets=()
for src in tests/fuzz/fuzz_*.c; do
    t=$(basename "$src" .c)
    targets+=("${t#fuzz_}")
done
out=$(mktemp)
trap 'rm -f "$out"' EXIT
echo "== fuzzing ${#targets[@]} targets, ${secs} s each, ${jobs} at a time"
set +e
printf '%s\n' "${targets[@]}" |
    FUZZ_NO_BUILD=1 xargs -P"$jobs" -I{} tools/fuzz.sh {} "$secs" >"$out"
rc=$?
set -e
printf '%-22s %6s %11s %8s %6s %7s %12s %8s\n' target secs executions exec/s cov ft corpus \
    findings
sort "$out"
bad=$(awk '$8 != 0' "$out" | wc -l)
missing=$(( ${#targets[@]} - $(wc -l <"$out") ))
echo "== fuzzing: build $((built - start)) s, runs $(($(date +%s) - built)) s;" \
    "$bad targets with findings, $missing without a result"
if [ "$rc" -ne 0 ] || [ "$bad" -ne 0 ] || [ "$missing" -ne 0 ]; then
    echo "check-fuzz: FAILED (logs and artifacts under build/fuzz/logs, build/fuzz/artifacts)" >&2
    exit 1
fi
