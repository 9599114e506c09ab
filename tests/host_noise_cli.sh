#!/bin/sh
# host_noise_cli.sh SC_HOST_NOISE: the host-noise probe (tools/rt_bench/host_noise.c) refuses
# bad arguments with exit 2 and, in a 1 s run, prints both jobs' rows with counts and ordered
# percentiles, and the steal line.
set -u
BIN=$1
fails=0
check() { if [ "$2" = "$3" ]; then echo "ok: $1"; else echo "FAIL: $1: exit $3, expected $2"; fails=$((fails + 1)); fi; }
for bad in "--threads 0" "--threads 99" "--rate 1.5" "--rate 0" "--seconds 0" "--seconds x" \
           "--mib -1" "--reps 101" "--nope 1" "--seconds"; do
    # shellcheck disable=SC2086 # the words are the arguments
    "$BIN" $bad > /dev/null 2>&1; check "refused: $bad" 2 $?
done
"$BIN" --help > /dev/null 2>&1; check "--help" 0 $?
out=$("$BIN" --seconds 1 --threads 1 --mib 4 --reps 1); check "a 1 s run" 0 $?
echo "$out"
for job in compute memory; do
    row=$(echo "$out" | awk -v j="$job" '$1 == j')
    # count > 30 (60 periods of 1 rep), 0 < min <= p50 <= p99 <= p99.9 <= worst
    echo "$row" | awk '{ exit !($2 > 30 && $3 > 0 && $3 <= $4 && $4 <= $5 && $5 <= $6 && $6 <= $7) }'
    check "$job row: count and ordered percentiles" 0 $?
done
echo "$out" | grep -q '^host steal during the run: '; check "steal line" 0 $?
[ "$fails" = 0 ] || { echo "$fails failed"; exit 1; }
echo "all passed"
