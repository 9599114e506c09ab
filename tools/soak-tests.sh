#!/usr/bin/env bash
# Steadiness check: builds the dev preset, then runs every HIL test (ctest label "hil") and
# every hostsim test (label "hostsim") N times in a row, one ctest round at a time. Stops after
# the first round with a failure (or a skip: a skipped test proves nothing) and prints that
# round's output, the failing test's included; prints a table of runs, passes, fails and skips
# per test at the end either way.
#   tools/soak-tests.sh [-n ROUNDS] [-j JOBS] [-l LABEL_REGEX]
#     -n ROUNDS       rounds (default 20)
#     -j JOBS         tests run in parallel within a round (default 1; at most 2 on a shared
#                     machine). The HIL tests share one VM lock (RESOURCE_LOCK hil_vm) and
#                     never overlap each other; with -j2 a hostsim test runs beside them.
#     -l LABEL_REGEX  ctest label regex (default "^(hil|hostsim)$")
# Exit 0 when every run of every test passed, 1 on a failure or skip, 2 on a usage error.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
rounds=20 jobs=1 labels='^(hil|hostsim)$'
while getopts "n:j:l:h" o; do
    case "$o" in
    n) rounds=$OPTARG ;;
    j) jobs=$OPTARG ;;
    l) labels=$OPTARG ;;
    *) sed -n '2,13p' "$0"; exit 2 ;;
    esac
done
[[ "$rounds" =~ ^[1-9][0-9]*$ && "$jobs" =~ ^[1-9][0-9]*$ ]] || { echo "soak: -n and -j take positive integers" >&2; exit 2; }

build="$top/build/dev"
log_dir="$build/soak"
rm -rf "$log_dir" && mkdir -p "$log_dir"
cmake --preset dev -S "$top" >/dev/null
cmake --build --preset dev -j2 >/dev/null

mapfile -t tests < <(ctest --test-dir "$build" -N -L "$labels" | sed -n 's/^ *Test *#[0-9]*: //p')
[ ${#tests[@]} -gt 0 ] || { echo "soak: no test matches label $labels" >&2; exit 2; }
declare -A runs passes fails skips
for t in "${tests[@]}"; do runs[$t]=0 passes[$t]=0 fails[$t]=0 skips[$t]=0; done

table() {
    printf '\n%-24s %6s %6s %6s %6s\n' test runs passes fails skips
    for t in "${tests[@]}"; do
        printf '%-24s %6d %6d %6d %6d\n' "$t" "${runs[$t]}" "${passes[$t]}" "${fails[$t]}" "${skips[$t]}"
    done
}

echo "soak: ${#tests[@]} tests (${tests[*]}), $rounds rounds, -j$jobs; logs in $log_dir"
start=$(date +%s)
bad=""
for ((r = 1; r <= rounds; r++)); do
    out="$log_dir/round-$r.txt"
    # no --stop-on-failure: a round's parallel tests finish and all of them are counted
    rc=0
    ctest --test-dir "$build" -L "$labels" -j "$jobs" --output-on-failure --timeout 900 \
        > "$out" 2>&1 || rc=$?
    # result lines: "1/8 Test #58: hil_can_socketcan ....   Passed   29.1 sec"
    while read -r name result; do
        [ -n "${runs[$name]+x}" ] || continue
        runs[$name]=$((runs[$name] + 1))
        case "$result" in
        Passed) passes[$name]=$((passes[$name] + 1)) ;;
        Skipped | Not*) skips[$name]=$((skips[$name] + 1)); bad="$bad $name" ;;
        *) fails[$name]=$((fails[$name] + 1)); bad="$bad $name" ;;
        esac
    done < <(sed -n 's/^ *[0-9]*\/[0-9]* *Test *#[0-9]*: \([^ ]*\) \.*[ *]*\([A-Za-z]*\).*/\1 \2/p' "$out")
    echo "soak: round $r/$rounds done after $(( $(date +%s) - start )) s (ctest rc $rc)"
    if [ -n "$bad" ] || [ "$rc" -ne 0 ]; then
        echo "soak: round $r: failed or skipped:${bad:- (ctest rc $rc)}; its output ($out):"
        cat "$out"
        table
        exit 1
    fi
done
table
echo "soak: PASS, $rounds rounds in $(( $(date +%s) - start )) s"
