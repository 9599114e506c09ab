#!/bin/sh
# rt_press.sh: deadline evidence with the probe pressing. The real frame loop (sonocomp, FEM
# and MSDS) is fed a replayed press-and-sweep tracker log (sc-tracker-emu --script sweep
# --log: the probe held DEPTH mm into the skin and swept 20 mm back and forth every 4 s) for
# SECONDS at 60 Hz and at 120 Hz, SCHED_FIFO, memory locked, the loop on CPU 0, while
# stress-ng (or a busy loop when stress-ng is missing) loads CPU 1. Per run: sonocomp's final
# table (frame time and wake-up lateness: mean, p50, p99, p99.9, worst; deadline misses) and
# the two histograms (OUT/hist-METHOD-RATEhz.csv, bins of 1/16 octave of microseconds), and
# every frame's times (OUT/trace-METHOD-RATEhz.csv: lateness, frame, missed, each stage, us),
# which tell slow frames at the script's press or folds from a host's spread over the run
# (tools/rt_bench/trace_summary.sh, printed after each run).
# Without SocketCAN the log is replayed in real time through --can-replay (tools/demo-live.sh).
# It takes 10 s + 4 x (SECONDS + ~5) s plus the case build (about 4.7 min at the default 60 s).
#
# usage: tools/rt_bench/rt_press.sh BUILD_DIR [SECONDS] [MESH NX,NY,NZ] [WORKERS] [OUT_DIR]
#   defaults: 60 s, the phantom neck-ijv at its own mesh, 1 worker, out/rt_press
# environment: RT_PRESS_LOAD=none leaves CPU 1 to the engine (a two-worker run uses both CPUs:
#   the loop on CPU 0, its worker on CPU 1); RT_PRESS_RATES="60" runs only the rates listed
#   (default "60 120"); RT_PRESS_METHODS="msds" runs only the methods listed (default "fem
#   msds"); RT_PRESS_SET="physics.cg_iterations=8 ..." passes each KEY=VALUE to sonocomp as -s.
# First the host's own spread (sc-host-noise: fixed work on the same CPUs for 10 s); after
# each run: the host's steal time over it (/proc/stat, all CPUs; the time the hypervisor
# ran something else on this VM's CPUs), so a slow run can be told from a preempted one.
set -eu
BUILD=$1
SECS=${2:-60}
MESH=${3:-}
WORKERS=${4:-1}
OUT=${5:-out/rt_press}
ENGINE=$BUILD/platform/linux/sonocomp
EMU=$BUILD/tools/tracker_emu/sc-tracker-emu
CB=$BUILD/tools/casebuild/sc-casebuild
NOISE=$BUILD/tools/rt_bench/sc-host-noise
for b in "$ENGINE" "$EMU" "$CB" "$NOISE"; do
    [ -x "$b" ] || { echo "rt_press: missing $b (build sonocomp sc-tracker-emu sc-casebuild sc-host-noise)"; exit 2; }
done
mkdir -p "$OUT"
CASE=$OUT/neck-ijv.scase
if [ -n "$MESH" ]; then
    "$CB" phantom neck-ijv --mesh-nodes "$MESH" -o "$CASE" > "$OUT/casebuild.log" 2>&1
else
    "$CB" phantom neck-ijv -o "$CASE" > "$OUT/casebuild.log" 2>&1
fi
LOG=$OUT/tracker.log
# the neck-ijv box top centre is volume (-2, 0, 0), tracker (x, -y, -z) (tools/demo-live.sh)
"$EMU" --script sweep --point -2,0,0 --depth-mm 8 --hover-mm 5 --length-mm 20 --period-s 4 \
    --duration-s $((SECS + 5)) --log "$LOG" 2> "$OUT/tracker.err"
hog=""
RATES=${RT_PRESS_RATES:-60 120}
if [ "${RT_PRESS_LOAD:-stress}" = none ]; then
    load="none (RT_PRESS_LOAD=none)"
elif command -v stress-ng > /dev/null 2>&1; then
    stress-ng --cpu 1 --taskset 1 --timeout $((4 * (SECS + 10)))s > /dev/null 2>&1 &
    hog=$!
    load="stress-ng --cpu 1 --taskset 1"
else
    taskset -c 1 sh -c 'while :; do :; done' &
    hog=$!
    load="busy loop on CPU 1 (no stress-ng)"
fi
trap '[ -n "$hog" ] && kill "$hog" 2> /dev/null; true' EXIT
echo "machine: $(nproc) CPUs, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')," \
    "load average $(cut -d' ' -f1-3 /proc/loadavg), kernel $(uname -r)"
if [ -n "$MESH" ]; then mesh_desc=$MESH; else mesh_desc="the phantom's own"; fi
sets=""
for kv in ${RT_PRESS_SET:-}; do
    case $kv in
        *=*) sets="$sets -s $kv" ;;
        *) echo "rt_press: RT_PRESS_SET wants KEY=VALUE words, got '$kv'"; exit 2 ;;
    esac
done
echo "second core: $load; mesh: $mesh_desc; workers: $WORKERS; $SECS s per run;" \
    "settings: ${RT_PRESS_SET:-the defaults}"
# the steal column of /proc/stat's cpu line, in USER_HZ ticks (0 where the kernel has none)
steal_ticks() { awk '/^cpu /{print ($9 == "" ? 0 : $9); exit}' /proc/stat 2> /dev/null || echo 0; }
hz=$(getconf CLK_TCK 2> /dev/null || echo 100)
# the host's own spread first: fixed work on the engine's CPUs in its duty cycle (host_noise.c)
echo "=== host noise: the same work every period, $WORKERS thread(s), 10 s ==="
"$NOISE" --seconds 10 --threads "$WORKERS" || echo "rt_press: sc-host-noise failed"
for method in ${RT_PRESS_METHODS:-fem msds}; do
    for rate in $RATES; do
        echo "=== $method at $rate Hz ==="
        st0=$(steal_ticks)
        # shellcheck disable=SC2086 # $sets is a list of -s KEY=VALUE words
        "$ENGINE" -s "case=$CASE" -s physics.method=$method -s frame_rate_hz=$rate $sets \
            -s display.target=none -s rt.cpu=0 -s rt.sched_fifo=true -s rt.mlock=true \
            -s watchdog.device=soft -s status.line=off -s log.level=error \
            --workers "$WORKERS" --can-replay "$LOG" --seconds "$SECS" \
            --hist "$OUT/hist-$method-${rate}hz.csv" --trace "$OUT/trace-$method-${rate}hz.csv" \
            2> "$OUT/sonocomp-$method-${rate}hz.err" |
            sed -n '/final statistics/,$p'
        st1=$(steal_ticks)
        echo "host steal during the run: $(( (st1 - st0) * 1000 / hz )) ms over all CPUs"
        "$(dirname "$0")/trace_summary.sh" "$OUT/trace-$method-${rate}hz.csv" 30 "$rate" ||
            echo "rt_press: no trace summary for $method at $rate Hz"
    done
done
