#!/usr/bin/env bash
# demo-live.sh BUILD_DIR OUT_DIR: the real loop on this host, no CAN needed.
#
#   sc-tracker-emu --script press ... --log  ->  candump -l log (a vein compression and release)
#   sonocomp --can-replay LOG (the real frame loop, FEM physics, case neck-ijv)
#       -> UDP display link on 127.0.0.1 -> sc-viewer --headless --record-png OUT_DIR/live
#
# Writes OUT_DIR/live/view_<frame>.png (every PNG_EVERY-th frame), the logs of each part and
# OUT_DIR/live/summary.txt (sonocomp's final statistics and the viewer's line accounting).
# Unprivileged or root (no SCHED_FIFO, no mlock asked), about 15 s. Exits non-zero with a
# message naming the part that failed. Environment: ENGINE_S (8), PNG_EVERY (6).
set -euo pipefail

die() { echo "demo-live: $*" >&2; exit 1; }
[ $# -eq 2 ] || { echo "usage: $0 BUILD_DIR OUT_DIR" >&2; exit 2; }
BUILD=$(cd "$1" && pwd) || die "no build directory $1"
mkdir -p "$2"
OUT=$(cd "$2" && pwd)
LIVE=$OUT/live
ENGINE_S=${ENGINE_S:-8}
PNG_EVERY=${PNG_EVERY:-6}

ENGINE=$BUILD/platform/linux/sonocomp
EMU=$BUILD/tools/tracker_emu/sc-tracker-emu
VIEWER=$BUILD/tools/viewer/sc-viewer
CASE=$BUILD/cases/neck-ijv.scase
for b in "$ENGINE" "$EMU" "$VIEWER"; do
    [ -x "$b" ] || die "missing $b (build the targets sonocomp sc-tracker-emu sc-viewer)"
done
rm -rf "$LIVE"
mkdir -p "$LIVE"
if [ ! -f "$CASE" ]; then
    # no built cases: generate the phantom with the case builder if it is there
    CB=$BUILD/tools/casebuild/sc-casebuild
    [ -x "$CB" ] || die "missing $CASE (build the target cases)"
    CASE=$LIVE/neck-ijv.scase
    "$CB" phantom neck-ijv -o "$CASE" > "$LIVE/casebuild.log" 2>&1 ||
        die "sc-casebuild failed, see $LIVE/casebuild.log"
fi

# (a) the tracker: press at the mesh box top centre of neck-ijv (tracker (x, y, z) is volume
#     (x, -y, -z); the box top centre is volume (-2, 0, 0)), 12 mm deep from 5 mm above
LOG=$LIVE/tracker.log
"$EMU" --script press --point -2,0,0 --depth-mm 12 --hover-mm 5 --duration-s 6 \
    --log "$LOG" 2> "$LIVE/tracker.err" || die "sc-tracker-emu failed: $(cat "$LIVE/tracker.err")"
[ -s "$LOG" ] || die "sc-tracker-emu wrote an empty log"

# (b) the viewer on a free-looking port of 127.0.0.1 (bounded: --seconds)
port=$((20000 + $(od -An -N2 -tu2 /dev/urandom | tr -d ' ') % 20000))
"$VIEWER" --headless --quiet --bind 127.0.0.1 --port "$port" --record-png "$LIVE" \
    --png-every "$PNG_EVERY" --idle 3 --seconds $((ENGINE_S + 20)) \
    > "$LIVE/viewer.out" 2> "$LIVE/viewer.err" &
vpid=$!
trap 'kill "$vpid" 2> /dev/null || true' EXIT
sleep 0.5
kill -0 "$vpid" 2> /dev/null || die "sc-viewer did not start: $(cat "$LIVE/viewer.err")"

# (c) the engine on the replayed log
set +e
"$ENGINE" -s "case=$CASE" -s physics.method=fem -s "display.target=udp:127.0.0.1:$port" \
    -s rt.sched_fifo=false -s rt.mlock=false -s watchdog.device=soft -s status.line=off \
    --can-replay "$LOG" --seconds "$ENGINE_S" > "$LIVE/sonocomp.out" 2> "$LIVE/sonocomp.err"
erc=$?
# (d) the viewer leaves 3 s after the last packet
wait "$vpid"
vrc=$?
set -e
trap - EXIT
[ "$erc" = 0 ] || die "sonocomp exited $erc: $(grep -m3 'level=error\|sonocomp:' "$LIVE/sonocomp.err")"
[ "$vrc" = 0 ] || die "sc-viewer exited $vrc: $(tail -3 "$LIVE/viewer.err")"
grep -q "event=case_loaded" "$LIVE/sonocomp.err" || die "sonocomp did not load $CASE"

field() { tr ' ' '\n' < "$2" | sed -n "s/^$1=//p"; }
frames=$(field frames "$LIVE/viewer.out")
lost=$(field lines_lost "$LIVE/viewer.out")
pngs=$(find "$LIVE" -name 'view_*.png' | wc -l)

# (e) the summary
{
    echo "demo-live: sonocomp on a replayed tracker log, B-scans over the UDP display link"
    echo "case $CASE, physics fem, $ENGINE_S s, viewer on 127.0.0.1:$port"
    echo "tracker: $(tail -1 "$LIVE/tracker.err")"
    echo
    cat "$LIVE/sonocomp.out"
    echo
    echo "viewer: $(cat "$LIVE/viewer.out")"
    echo "PNGs written: $pngs (every $PNG_EVERY-th frame) in $LIVE"
} > "$LIVE/summary.txt"

[ "${frames:-0}" -gt 0 ] || die "the viewer received no frame"
[ "$pngs" -gt 0 ] || die "no PNG written"
echo "demo-live: $frames frames received, $lost lines lost, $pngs PNGs; summary $LIVE/summary.txt"
