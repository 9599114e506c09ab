#!/bin/sh
# dlink_loopback.sh VIEWER SENDER WORKDIR: the display link end to end over 127.0.0.1, with the
# real programs: sc-dlink-send (platform/linux/sc_udp_display.c) -> UDP -> sc-viewer
# (platform/dlink/sc_dlink.c assembler). Checks:
#  1. nothing injected: every line of every frame arrives (lines_lost = 0, all frames complete);
#  2. 2% loss injected at the sender: the viewer counts exactly the injected lines as lost;
#  3. the viewer's recordings exist (PNG frames, an animated GIF with frames in it);
#  4. the viewer accepts datagrams only from its configured sender: with --sender 127.0.0.2
#     every datagram of the sender (from 127.0.0.1) is refused and counted, no frame is shown;
#     a non-loopback --bind without --sender is a usage error.
set -eu
VIEWER=$1
SENDER=$2
WORK=$3
rm -rf "$WORK" && mkdir -p "$WORK/png"
FRAMES=90
LINES=256

field() { # field NAME FILE: value of NAME=... in the key=value line of FILE
    tr ' ' '\n' < "$2" | sed -n "s/^$1=//p"
}

run_pair() { # run_pair TAG DROP_PERMILLE [viewer options...]
    tag=$1; drop=$2; shift 2
    port=$(( 20000 + $(od -An -N2 -tu2 /dev/urandom | tr -d ' ') % 20000 ))
    "$VIEWER" --headless --quiet --port "$port" --bind 127.0.0.1 --frames "$FRAMES" \
        --seconds 60 --idle 5 "$@" > "$WORK/$tag.viewer" 2> "$WORK/$tag.viewer.err" &
    vpid=$!
    sleep 0.5 # the viewer binds its socket
    "$SENDER" --target "127.0.0.1:$port" --frames "$FRAMES" --rate 60 --lines "$LINES" \
        --samples 256 --drop-permille "$drop" --seed 7 > "$WORK/$tag.sender"
    wait "$vpid"
    echo "[$tag] sender: $(cat "$WORK/$tag.sender")"
    echo "[$tag] viewer: $(cat "$WORK/$tag.viewer")"
}

fail() { echo "FAIL: $*"; exit 1; }

run_pair clean 0 --record-png "$WORK/png" --png-every 30 --gif "$WORK/session.gif" --gif-every 10
[ "$(field frames "$WORK/clean.viewer")" = "$FRAMES" ] || fail "clean: viewer frames"
[ "$(field complete "$WORK/clean.viewer")" = "$FRAMES" ] || fail "clean: incomplete frames"
[ "$(field lines_lost "$WORK/clean.viewer")" = 0 ] || fail "clean: lines lost"
[ "$(field lines_received "$WORK/clean.viewer")" = $((FRAMES * LINES)) ] || fail "clean: lines received"
[ "$(field rejected "$WORK/clean.viewer")" = 0 ] || fail "clean: rejected packets"
[ "$(field rej_sender "$WORK/clean.viewer")" = 0 ] || fail "clean: datagrams refused by sender"
[ "$(field lines_dropped "$WORK/clean.sender")" = 0 ] || fail "clean: sender dropped lines"
ls "$WORK"/png/view_*.png > /dev/null 2>&1 || fail "no PNG recorded"
[ "$(field gif_frames "$WORK/clean.viewer")" -ge 1 ] || fail "no GIF frames"
head -c 6 "$WORK/session.gif" | grep -q GIF89a || fail "GIF header"

run_pair lossy 20
injected=$(field lines_injected "$WORK/lossy.sender")
[ "$injected" -gt 0 ] || fail "lossy: nothing injected"
[ "$(field lines_dropped "$WORK/lossy.sender")" = 0 ] || fail "lossy: sender dropped lines besides the injected ones"
[ "$(field lines_lost "$WORK/lossy.viewer")" = "$injected" ] || fail "lossy: viewer lost $(field lines_lost "$WORK/lossy.viewer") lines, $injected injected"
[ "$(field frames "$WORK/lossy.viewer")" = "$FRAMES" ] || fail "lossy: viewer frames"
FRAMES=10
run_pair foreign 0 --sender 127.0.0.2 --seconds 3
# every datagram: per frame LINES line packets, a frame begin and a frame end
refused=$(field rej_sender "$WORK/foreign.viewer")
[ "$refused" = $((FRAMES * (LINES + 2))) ] || fail "foreign sender: $refused datagrams refused"
[ "$(field frames "$WORK/foreign.viewer")" = 0 ] || fail "foreign sender: frames shown"
[ "$(field lines_received "$WORK/foreign.viewer")" = 0 ] || fail "foreign sender: lines taken"
grep -q "refused .* datagrams from senders other than 127.0.0.2 (last from 127.0.0.1)" \
    "$WORK/foreign.viewer.err" || fail "foreign sender: not reported"
set +e
"$VIEWER" --headless --quiet --bind 0.0.0.0 --seconds 1 > /dev/null 2> "$WORK/anybind.err"
rc=$?
set -e
[ "$rc" = 2 ] || fail "--bind 0.0.0.0 without --sender: exit $rc, expected 2"
grep -q "not a loopback address" "$WORK/anybind.err" || fail "--bind 0.0.0.0: no reason given"
echo "PASS: no loss without injection; exactly $injected injected lines counted lost; $refused datagrams from a foreign sender refused"
