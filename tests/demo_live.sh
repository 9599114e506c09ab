#!/bin/sh
# demo_live.sh DEMO_LIVE_SCRIPT BUILD_DIR OUT_DIR: runs tools/demo-live.sh and checks its
# result: the script succeeded, the viewer closed frames, every frame complete with no display
# link line lost, the engine's CAN replay delivered the whole tracker log, at least one PNG.
set -eu
DEMO=$1
BUILD=$2
OUT=$3
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$OUT"
"$DEMO" "$BUILD" "$OUT" || fail "demo-live.sh exited $?"
LIVE=$OUT/live
[ -f "$LIVE/summary.txt" ] || fail "no summary.txt"
cat "$LIVE/summary.txt"
field() { tr ' ' '\n' < "$2" | sed -n "s/^$1=//p"; }
frames=$(field frames "$LIVE/viewer.out")
[ "${frames:-0}" -gt 0 ] || fail "viewer received no frame"
[ "$(field lines_lost "$LIVE/viewer.out")" = 0 ] || fail "display link lines lost"
[ "$(field incomplete "$LIVE/viewer.out")" = 0 ] || fail "incomplete frames"
[ "$(field lines_received "$LIVE/viewer.out")" -gt 0 ] || fail "no line received"
grep -q "delivered (end of log reached), 0 malformed lines refused" "$LIVE/sonocomp.out" ||
    fail "the CAN replay did not deliver the whole tracker log"
grep -q "CAN rx frames [1-9]" "$LIVE/sonocomp.out" || fail "the engine received no CAN frame"
pngs=$(find "$LIVE" -name 'view_*.png' | wc -l)
[ "$pngs" -gt 0 ] || fail "no PNG written"
echo "PASS: $frames frames, no line lost, $pngs PNGs"
