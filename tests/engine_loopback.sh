#!/bin/sh
# engine_loopback.sh SONOCOMP VIEWER CASEBUILD WORKDIR: the real engine binary streams its
# B-scans over the display link to sc-viewer on 127.0.0.1 (case: the neck phantom, no CAN, no
# real-time privileges asked). Nothing injected: every line of every frame arrives. With
# --inject-loss: the viewer counts exactly the lines the engine's sink lost on purpose.
set -eu
ENGINE=$1
VIEWER=$2
CASEBUILD=$3
WORK=$4
rm -rf "$WORK" && mkdir -p "$WORK"
"$CASEBUILD" phantom neck-ijv -o "$WORK/neck-ijv.scase" > "$WORK/casebuild.log" 2>&1
FRAMES=60
LINES=128

field() { tr ' ' '\n' < "$2" | sed -n "s/^$1=//p"; }
fail() { echo "FAIL: $*"; exit 1; }

run() { # run TAG INJECT_PERMILLE
    port=$(( 20000 + $(od -An -N2 -tu2 /dev/urandom | tr -d ' ') % 20000 ))
    "$VIEWER" --headless --quiet --bind 127.0.0.1 --port "$port" --frames "$FRAMES" \
        --seconds 120 --idle 10 > "$WORK/$1.viewer" 2>&1 &
    vpid=$!
    sleep 0.5
    "$ENGINE" -s can.interface=none -s "display.target=udp:127.0.0.1:$port" \
        -s "case=$WORK/neck-ijv.scase" -s rt.sched_fifo=false -s rt.mlock=false \
        -s status.line=off -s image.lines=$LINES -s watchdog.device=none \
        --frames "$FRAMES" --inject-loss "$2" > "$WORK/$1.engine" 2> "$WORK/$1.engine.err"
    wait "$vpid"
    grep "lines_sent=" "$WORK/$1.engine" > "$WORK/$1.link"
    echo "[$1] engine: $(cat "$WORK/$1.link")"
    echo "[$1] viewer: $(cat "$WORK/$1.viewer")"
}

run clean 0
grep -q "event=case_loaded case=" "$WORK/clean.engine.err" || fail "case not loaded"
[ "$(field frames "$WORK/clean.viewer")" = "$FRAMES" ] || fail "clean: frames"
[ "$(field lines_lost "$WORK/clean.viewer")" = 0 ] || fail "clean: lines lost"
[ "$(field lines_received "$WORK/clean.viewer")" = $((FRAMES * LINES)) ] || fail "clean: lines received"
[ "$(field lines_dropped "$WORK/clean.link")" = 0 ] || fail "clean: engine sink dropped lines"

run lossy 25
injected=$(field lines_injected "$WORK/lossy.link")
[ "$injected" -gt 0 ] || fail "lossy: nothing injected"
[ "$(field lines_dropped "$WORK/lossy.link")" = 0 ] || fail "lossy: engine sink dropped lines"
[ "$(field lines_lost "$WORK/lossy.viewer")" = "$injected" ] || fail "lossy: viewer lost $(field lines_lost "$WORK/lossy.viewer"), $injected injected"
echo "PASS: engine -> UDP -> viewer: no loss clean; exactly $injected injected lines counted lost"
