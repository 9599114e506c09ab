#!/bin/sh
# viewer_xvfb.sh VIEWER SENDER XWD_PROBE WORKDIR: sc-viewer with a real SDL2 window on a
# virtual X server (Xvfb, its screen mapped to a file with -fbdir), fed by sc-dlink-send's test
# pattern. The X server's own framebuffer is then checked, not the viewer's memory: the vein
# (dark ellipse at a known place of the pattern, fully open in the last frame) is visible
# against the tissue around it, and the overlay text is drawn. Exit 77 (skipped) without Xvfb.
set -u
VIEWER=$1
SENDER=$2
PROBE=$3
WORK=$4
command -v Xvfb > /dev/null 2>&1 || { echo "SKIP: Xvfb not installed (apt-get install xvfb)"; exit 77; }
rm -rf "$WORK" && mkdir -p "$WORK/fb"
rnd=$(od -An -N2 -tu2 /dev/urandom | tr -d ' ')
disp=":$(( 100 + rnd % 800 ))"
port=$(( 20000 + rnd % 20000 ))
Xvfb "$disp" -screen 0 640x640x24 -fbdir "$WORK/fb" -nolisten tcp > "$WORK/xvfb.log" 2>&1 &
xpid=$!
cleanup() { kill "$xpid" 2> /dev/null; wait "$xpid" 2> /dev/null; }
trap cleanup EXIT
for _ in $(seq 50); do [ -f "$WORK/fb/Xvfb_screen0" ] && break; sleep 0.1; done
[ -f "$WORK/fb/Xvfb_screen0" ] || { echo "FAIL: Xvfb did not start"; cat "$WORK/xvfb.log"; exit 1; }

# 121 frames at 60 Hz: the pattern's vein is open again in the last one (2 s cycle)
# (sanitizer builds: the X11 and GL driver libraries SDL loads leak at exit; not ours)
DISPLAY=$disp ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0" "$VIEWER" --port "$port" --bind 127.0.0.1 --frames 121 --seconds 60 --hold 3 \
    --size 640x640 --quiet > "$WORK/viewer.out" 2> "$WORK/viewer.err" &
vpid=$!
sleep 1
"$SENDER" --target "127.0.0.1:$port" --frames 121 --rate 60 --lines 256 --samples 384 \
    > "$WORK/sender.out"
sleep 1.5 # inside --hold: the window shows the last frame
cp "$WORK/fb/Xvfb_screen0" "$WORK/screen.xwd"
wait "$vpid"
status=$?
echo "viewer: $(cat "$WORK/viewer.out")"
if grep -q headless "$WORK/viewer.err"; then
    echo "FAIL: the viewer did not open a window:"; cat "$WORK/viewer.err"; exit 1
fi
[ "$status" = 0 ] || { echo "FAIL: viewer exit $status"; cat "$WORK/viewer.err"; exit 1; }
# Geometry of the pattern (linear, 38 mm x 40 mm in 640x640: 0.0625 mm/px, image columns
# 16..623): vein centre at 35% of the width, 45% of the depth -> (229, 288), half-height 4.8 mm
# = 77 px; tissue below it at 70% depth -> (229, 448); overlay text in the top 40 rows.
"$PROBE" "$WORK/screen.xwd" \
    dark 229 288 8 30 \
    bright 229 448 8 35 \
    contrast 229 288 229 448 8 30 \
    contrast 229 288 110 288 8 30 \
    text 0 0 639 40 150
