#!/bin/sh
# bench_paper_smoke.sh BENCH CHECK WORKDIR: bench-paper at its smallest settings, then its
# outputs checked (no timing asserted):
#  1. exit status 0 and both tables printed;
#  2. the CSV: header and 18 fields per row, one row per mesh x method x workers x run (2 x 2 x
#     2 x 2 = 16) plus Bullet's 2 x 2 when it was built in (bench-paper-check);
#  3. Fig. 9, wall and CPU: PNGs that decode, with bars (bench-paper-check);
#  4. the output sink wrote B-scan frames (PNG files in the sink's folder).
set -eu
BENCH=$1
CHECK=$2
WORK=$3
rm -rf "$WORK" && mkdir -p "$WORK"
"$BENCH" --frames 2 --repeats 2 --meshes 8x4x4,10x5x5 --workers 1,2 --methods msds,fem \
    --sink png --png-dir "$WORK/frames" --csv "$WORK/bench.csv" --png "$WORK/fig9.png" --png-cpu "$WORK/fig9-cpu.png" \
    > "$WORK/stdout.txt" 2> "$WORK/stderr.txt" || {
    echo "bench-paper failed:"; cat "$WORK/stderr.txt"; exit 1; }
grep -q "^Table I " "$WORK/stdout.txt" || { echo "no Table I"; exit 1; }
grep -q "^Table II " "$WORK/stdout.txt" || { echo "no Table II"; exit 1; }
rows=16
if grep -q "Bullet was not found" "$WORK/stdout.txt"; then
    echo "bench_paper_smoke: Bullet not built in, its rows not expected"
    if grep -q ",bullet," "$WORK/bench.csv"; then echo "Bullet rows without Bullet"; exit 1; fi
else
    rows=20
    n=$(grep -c ",bullet," "$WORK/bench.csv" || true)
    [ "$n" -eq 4 ] || { echo "expected 4 Bullet rows, found $n"; exit 1; }
fi
total=$(($(wc -l < "$WORK/bench.csv") - 1))
[ "$total" -eq "$rows" ] || { echo "expected $rows CSV rows, found $total"; exit 1; }
"$CHECK" "$WORK/bench.csv" "$WORK/fig9.png" "$rows"
"$CHECK" "$WORK/bench.csv" "$WORK/fig9-cpu.png" "$rows"
n=$(find "$WORK/frames" -name 'frame_*.png' | wc -l)
[ "$n" -ge 1 ] || { echo "the PNG sink wrote no frame"; exit 1; }
echo "bench_paper_smoke: ok ($rows rows, $n sink frames)"
