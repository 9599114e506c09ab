#!/bin/sh
# rt_bench.sh: the frame loop's deadline statistics on this machine, as the appliance runs it:
# sonocomp at 60 Hz, SCHED_FIFO, memory locked, pinned to CPU 0, lines streamed over UDP to a
# headless sc-viewer, while a busy loop loads CPU 1 (and whatever else runs on the machine).
# Prints sonocomp's final statistics table (frame time, wake-up latency, misses, stages) and
# the viewer's line accounting.
#
# usage: tools/rt_bench/rt_bench.sh BUILD_DIR CASE_FILE [SECONDS] [load|noload]
set -eu
BUILD=$1
CASE=$2
SECONDS_RUN=${3:-60}
LOAD=${4:-load}
ENGINE=$BUILD/platform/linux/sonocomp
VIEWER=$BUILD/tools/viewer/sc-viewer
[ -x "$ENGINE" ] && [ -x "$VIEWER" ] || { echo "build sonocomp and sc-viewer in $BUILD first"; exit 2; }
port=$(( 20000 + $(od -An -N2 -tu2 /dev/urandom | tr -d ' ') % 20000 ))
hog=""
if [ "$LOAD" = load ]; then
    taskset -c 1 sh -c 'while :; do :; done' &
    hog=$!
fi
cleanup() { [ -n "$hog" ] && kill "$hog" 2> /dev/null; true; }
trap cleanup EXIT
"$VIEWER" --headless --quiet --bind 127.0.0.1 --port "$port" --seconds $((SECONDS_RUN + 10)) \
    --idle 3 > /tmp/rt_bench_viewer.$$ 2>&1 &
vpid=$!
sleep 0.5
echo "machine: $(nproc) CPUs, load average $(cut -d' ' -f1-3 /proc/loadavg), kernel $(uname -r)"
echo "second core: $LOAD"
"$ENGINE" -s can.interface=none -s "display.target=udp:127.0.0.1:$port" -s "case=$CASE" \
    -s rt.cpu=0 -s rt.sched_fifo=true -s rt.mlock=true -s status.line=off -s log.level=error \
    --seconds "$SECONDS_RUN"
wait "$vpid" || true
echo "viewer: $(cat /tmp/rt_bench_viewer.$$)"
rm -f /tmp/rt_bench_viewer.$$
