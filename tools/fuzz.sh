#!/usr/bin/env bash
# Runs one libFuzzer target of the fuzz preset (tests/fuzz/fuzz_<name>.c) for a while:
#   tools/fuzz.sh TARGET SECONDS [libFuzzer options...]
# TARGET is fuzz_<name> or <name> (tools/fuzz.sh sc_case 3600). Builds the fuzz preset first
# when the binary is missing (FUZZ_NO_BUILD=1: never). The fuzzer starts from the checked-in
# corpus tests/fuzz/corpus/<name>/ (read only) and the working corpus
# build/fuzz/corpus/<name>/, where it keeps what it finds (not in git: copy the few inputs
# worth keeping into tests/fuzz/corpus/<name>/). A crash, leak, timeout or out-of-memory input
# lands in build/fuzz/artifacts/<name>/: fix it, then commit it as
# tests/fuzz/regress/<name>/<what>, which the smoke test replays under ctest. A dictionary
# tests/fuzz/fuzz_<name>.dict is used when present.
# Prints one table row (target, seconds, executions, exec/s, coverage edges (cov), features
# (ft), corpus size, findings), the log is build/fuzz/logs/<name>.log. Exit 0 when there was
# no finding, 1 otherwise, 2 on a usage or build error.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
if [ $# -lt 2 ]; then
    echo "usage: $0 TARGET SECONDS [libFuzzer options...]" >&2
    exit 2
fi
name=${1#fuzz_}
secs=$2
shift 2
case "$secs" in
'' | *[!0-9]*) echo "fuzz.sh: SECONDS must be a whole number" >&2; exit 2 ;;
esac
build=${FUZZ_BUILD_DIR:-$top/build/fuzz}
bin=$build/tests/fuzz_${name}_libfuzzer
if [ ! -f "$top/tests/fuzz/fuzz_$name.c" ]; then
    echo "fuzz.sh: no target tests/fuzz/fuzz_$name.c" >&2
    exit 2
fi
if [ ! -x "$bin" ]; then
    if [ "${FUZZ_NO_BUILD:-0}" = 1 ]; then
        echo "fuzz.sh: $bin missing" >&2
        exit 2
    fi
    (cd "$top" && cmake --preset fuzz >/dev/null &&
        cmake --build --preset fuzz -j"$(nproc)" >/dev/null) || exit 2
fi
work=$build/corpus/$name
arts=$build/artifacts/$name
logs=$build/logs
mkdir -p "$work" "$arts" "$logs"
log=$logs/$name.log
seeds=$top/tests/fuzz/corpus/$name
dirs=("$work")
[ -d "$seeds" ] && dirs+=("$seeds")
opts=(-max_total_time="$secs" -print_final_stats=1 -timeout=10 -rss_limit_mb=2048
      -max_len=65536 -artifact_prefix="$arts/")
[ -f "$top/tests/fuzz/fuzz_$name.dict" ] && opts+=(-dict="$top/tests/fuzz/fuzz_$name.dict")
before=$(find "$arts" -type f | wc -l)
set +e
ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} \
UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1} \
    "$bin" "${opts[@]}" "$@" "${dirs[@]}" >"$log" 2>&1
rc=$?
set -e
after=$(find "$arts" -type f | wc -l)
findings=$((after - before))
if [ "$rc" -ne 0 ] && [ "$findings" -eq 0 ]; then
    findings=1 # a failure without an artifact (e.g. a crash while reading the corpus)
fi
last=$(grep -E '^#[0-9]+' "$log" | grep -E 'cov: ' | tail -1 || true)
execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
[ -n "$execs" ] || execs=$(echo "$last" | sed -n 's/^#\([0-9]*\).*/\1/p')
rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
cov=$(echo "$last" | sed -n 's/.* cov: \([0-9]*\).*/\1/p')
ft=$(echo "$last" | sed -n 's/.* ft: \([0-9]*\).*/\1/p')
corp=$(echo "$last" | sed -n 's/.* corp: \([^ ]*\).*/\1/p')
printf '%-22s %6s %11s %8s %6s %7s %12s %8s\n' "$name" "$secs" "${execs:-?}" "${rate:-?}" \
    "${cov:-?}" "${ft:-?}" "${corp:-?}" "$findings"
if [ "$findings" -ne 0 ]; then
    echo "fuzz.sh: $name: FINDING (exit $rc), log $log, artifacts in $arts:" >&2
    grep -E 'ERROR: |runtime error|fuzz invariant failed|SUMMARY|Test unit written' "$log" |
        head -8 >&2 || true
    exit 1
fi
