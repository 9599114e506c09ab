#!/bin/sh
# auth_cli.sh SONOCOMP TRACKER_EMU WORKDIR: authenticated commands end to end between two
# programs: sc-tracker-emu signs a freshness sync and two commands with Mbed TLS's AES-CMAC into a
# candump log; sonocomp replays it and its core verifies them. Checked from sonocomp's final
# report: the right key applies both commands; a wrong key refuses all three (bad MAC, then not
# synchronised); the log replayed a second time after the first (time shifted) is stale; the
# log without its cryptographic PDUs leaves every command without its MAC.
set -u
BIN=$1
EMU=$2
WORK=$3
rm -rf "$WORK" && mkdir -p "$WORK"
fails=0
contains() { # contains DESCRIPTION FILE TEXT
    if grep -qF -- "$3" "$2"; then echo "ok: $1"; else
        echo "FAIL: $1: '$3' not in $2:"; sed 's/^/    /' "$2"; fails=$((fails + 1)); fi
}
NODEV="-s can.interface=none -s display.target=none -s rt.sched_fifo=false -s rt.mlock=false -s status.line=off -s case=$WORK/none.scase"
run() { # run NAME LOG FRAMES [--set ...]: sonocomp replays LOG for FRAMES frames (60 Hz)
    name=$1 log=$2 frames=$3
    shift 3
    # shellcheck disable=SC2086
    "$BIN" $NODEV "$@" --can-replay "$log" --frames "$frames" > "$WORK/$name.out" 2> "$WORK/$name.err"
    echo "$name: exit $?"
}
"$EMU" --script press --duration-s 2 --log "$WORK/cmd.log" \
    --command method=fem@0.5 --command reset=faults@1.0 2> "$WORK/emu.err" || {
    echo "FAIL: the emulator"; cat "$WORK/emu.err"; exit 1; }
contains "emulator sent two commands" "$WORK/emu.err" "commands_sent=2"

run good "$WORK/cmd.log" 180
contains "right key: both applied" "$WORK/good.out" "commands applied 2, refused 0"
contains "right key: sync and commands authenticated" "$WORK/good.out" \
    "command authentication: 3 authenticated, 0 refused"

run wrongkey "$WORK/cmd.log" 180 -s can.auth_key=000102030405060708090a0b0c0d0e0f
contains "wrong key: nothing applied" "$WORK/wrongkey.out" "commands applied 0, refused 0"
contains "wrong key: refused by reason" "$WORK/wrongkey.out" \
    "0 authenticated, 3 refused (bad MAC 1, stale 0, not synced 2,"

# the same log again 1 s after its end (3 s after its start) (a replay of a recording): stale
awk '{ t = substr($1, 2, length($1) - 2) + 3.0; printf "(%.6f) %s %s\n", t, $2, $3 }' \
    "$WORK/cmd.log" > "$WORK/later.log"
cat "$WORK/cmd.log" "$WORK/later.log" > "$WORK/twice.log"
run twice "$WORK/twice.log" 360
contains "replayed log: only the first copy applied" "$WORK/twice.out" "commands applied 2, refused 0"
contains "replayed log: the copy is stale" "$WORK/twice.out" \
    "3 authenticated, 3 refused (bad MAC 0, stale 3,"

# without the cryptographic PDUs (ids 0x088..0x08C): every command lacks its MAC
grep -v -E ' 08[89ABC]#' "$WORK/cmd.log" > "$WORK/nomac.log"
run nomac "$WORK/nomac.log" 180
contains "no MAC: nothing applied" "$WORK/nomac.out" "commands applied 0, refused 0"
contains "no MAC: counted missing" "$WORK/nomac.out" "orphan MAC 0, MAC missing 3)"

[ "$fails" = 0 ] && echo "PASS" && exit 0
echo "$fails checks failed"; exit 1
