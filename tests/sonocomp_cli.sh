#!/bin/sh
# sonocomp_cli.sh SONOCOMP SOURCE_DIR WORKDIR [CASE]: the engine binary's command line and exit
# conventions: --help/--version, usage errors (2), every refused configuration line reported
# with file:line: key: reason (3), --check-config, a bounded run with a final report (0), a clean
# stop on SIGTERM (0), a missing CAN interface (1); with CASE (a built case file), the solver's
# configured CG budget reaching the engine.
set -u
BIN=$1
SRC=$2
WORK=$3
CASE=${4:-}
rm -rf "$WORK" && mkdir -p "$WORK"
fails=0
check() { # check DESCRIPTION EXPECTED_STATUS ACTUAL_STATUS
    if [ "$2" != "$3" ]; then
        echo "FAIL: $1: exit $3, expected $2"
        fails=$((fails + 1))
    else
        echo "ok: $1"
    fi
}
contains() { # contains DESCRIPTION FILE TEXT
    if grep -qF -- "$3" "$2"; then echo "ok: $1"; else
        echo "FAIL: $1: '$3' not in $2:"; sed 's/^/    /' "$2"; fails=$((fails + 1)); fi
}
# no RT privileges asked for, no devices: runs anywhere
NODEV="-s can.interface=none -s display.target=none -s rt.sched_fifo=false -s rt.mlock=false -s status.line=off -s case=$WORK/none.scase"

"$BIN" --help > "$WORK/help" 2>&1; check "--help" 0 $?
contains "--help text" "$WORK/help" "usage: sonocomp"
"$BIN" --version > "$WORK/version" 2>&1; check "--version" 0 $?
contains "--version text" "$WORK/version" "sonocomp "
"$BIN" --no-such-option > /dev/null 2>&1; check "unknown option" 2 $?
"$BIN" extra-argument > /dev/null 2>&1; check "stray argument" 2 $?
"$BIN" --frames -3 > /dev/null 2>&1; check "--frames -3" 2 $?
"$BIN" --help-config > "$WORK/keys" 2>&1; check "--help-config" 0 $?
contains "--help-config lists ranges" "$WORK/keys" "integer 1 .. 240"

cat > "$WORK/bad.conf" <<'CONF'
# three bad lines among good ones
image.depth_mm = 50
frame_rate_hz = 500
physics.method = sph

display.target = udp:127.0.0.1
CONF
"$BIN" -c "$WORK/bad.conf" > "$WORK/bad.out" 2> "$WORK/bad.err"; check "bad configuration" 3 $?
contains "line 3 reported" "$WORK/bad.err" "bad.conf:3: frame_rate_hz: 500 is outside 1 .. 240 (SC_ERR_CFG_RANGE)"
contains "line 4 reported" "$WORK/bad.err" "bad.conf:4: physics.method: sph is not one of msds | fem (SC_ERR_CFG_VALUE)"
contains "line 6 reported" "$WORK/bad.err" "bad.conf:6: display.target:"
"$BIN" -c "$WORK/missing.conf" > /dev/null 2>&1; check "missing configuration file" 3 $?
"$BIN" -s frame_rate_hz=0 --check-config > /dev/null 2>&1; check "--set out of range" 3 $?
"$BIN" -s nokey > /dev/null 2>&1; check "--set without =" 3 $?
"$BIN" -c "$SRC/config/sonocomp.conf" -s frame_rate_hz=30 --check-config > "$WORK/eff" 2>&1
check "--check-config of the default file" 0 $?
contains "--set overrides the file" "$WORK/eff" "frame_rate_hz = 30"
contains "file values shown" "$WORK/eff" "display.target = udp:127.0.0.1:5600"

# shellcheck disable=SC2086
"$BIN" $NODEV --frames 5 > "$WORK/run.out" 2> "$WORK/run.err"; check "bounded run" 0 $?
contains "final report" "$WORK/run.out" "sonocomp final statistics"
contains "stopped by the frame limit" "$WORK/run.out" "stopped by frame limit"
contains "5 frames run" "$WORK/run.out" "; 5 frames at 60 Hz"
contains "structured log" "$WORK/run.err" "level=info event=start"
contains "missing case logged" "$WORK/run.err" "event=case_load_failed"

"$BIN" -s physics.cg_iterations=0 --check-config > /dev/null 2> "$WORK/cg.err"
check "physics.cg_iterations 0 refused" 3 $?
contains "physics.cg_iterations range named" "$WORK/cg.err" "physics.cg_iterations=0: 0 is outside 1 .. "
if [ -n "$CASE" ] && [ -f "$CASE" ]; then
    RUNC="-s can.interface=none -s display.target=none -s rt.sched_fifo=false -s rt.mlock=false -s status.line=off -s case=$CASE"
    # shellcheck disable=SC2086
    "$BIN" $RUNC --frames 2 > "$WORK/cg10.out" 2>&1; check "run on $CASE" 0 $?
    contains "the default CG budget in the report" "$WORK/cg10.out" "10 CG iterations per frame"
    # shellcheck disable=SC2086
    "$BIN" $RUNC -s physics.cg_iterations=7 -s physics.method=fem --frames 2 > "$WORK/cg7.out" 2>&1
    check "run with physics.cg_iterations=7" 0 $?
    contains "the configured method reaches the engine" "$WORK/cg7.out" "soft tissue: fem, mesh "
    contains "the configured CG budget reaches the engine" "$WORK/cg7.out" ", 7 CG iterations per frame"
else
    echo "FAIL: no case file '$CASE' (build the target cases)"
    fails=$((fails + 1))
fi

# shellcheck disable=SC2086
"$BIN" $NODEV > "$WORK/term.out" 2> "$WORK/term.err" &
pid=$!
sleep 1.5
kill -TERM "$pid"
wait "$pid"; check "SIGTERM stops cleanly" 0 $?
contains "stopped by SIGTERM" "$WORK/term.out" "stopped by SIGTERM"
contains "stop record logged" "$WORK/term.err" "event=stop reason=\"SIGTERM\""

"$BIN" -s can.interface=nosuchcan0 -s display.target=none -s rt.sched_fifo=false \
    -s rt.mlock=false --frames 1 > /dev/null 2> "$WORK/can.err"; check "missing CAN interface" 1 $?
contains "CAN failure named" "$WORK/can.err" "event=can_open_failed interface=nosuchcan0"

# --can-replay: a missing log is a runtime error with the file named; a short log replays
# (can.interface ignored: a missing interface does not matter then)
# shellcheck disable=SC2086
"$BIN" $NODEV --can-replay "$WORK/no-such.log" --frames 1 > /dev/null 2> "$WORK/replay.err"
check "--can-replay of a missing file" 1 $?
contains "missing replay file named" "$WORK/replay.err" "sonocomp: --can-replay $WORK/no-such.log: No such file or directory"
printf '(1700000000.000000) vcan0 123#0102\nnot a line\n' > "$WORK/short.log"
# shellcheck disable=SC2086
"$BIN" $NODEV -s can.interface=nosuchcan0 --can-replay "$WORK/short.log" --frames 3 \
    > "$WORK/replay.out" 2> "$WORK/replay2.err"; check "--can-replay of a short log" 0 $?
contains "replay reported" "$WORK/replay.out" "1 frames over 0.000 s, 1 delivered (end of log reached), 1 malformed lines refused"
contains "replay rejects logged" "$WORK/replay2.err" "event=can_replay_rejected"

# --trace: every frame's times as CSV (a header, a row per frame, the stages named); a path
# that cannot be written is refused before the run, named
# shellcheck disable=SC2086
"$BIN" $NODEV --frames 7 --trace "$WORK/trace.csv" > "$WORK/trace.out" 2>&1; check "--trace run" 0 $?
contains "trace reported" "$WORK/trace.out" "7 frames written to $WORK/trace.csv, 0 past its capacity not kept"
contains "trace header" "$WORK/trace.csv" "frame,wakeup_late_us,frame_us,missed,rx_us,physics_us,imaging_us"
rows=$(tail -n +2 "$WORK/trace.csv" | grep -c '^[0-9][0-9]*,[0-9]')
check "trace rows (one per frame)" 7 "$rows"
last=$(tail -n 1 "$WORK/trace.csv" | cut -d, -f1)
check "trace frames numbered from 0" 6 "$last"
# the trace's summary (tools/rt_bench/trace_summary.sh, which rt_press prints after each run)
"$SRC/tools/rt_bench/trace_summary.sh" "$WORK/trace.csv" 3 60 > "$WORK/tsum.out" 2>&1
check "trace summary" 0 $?
contains "trace summary counts the frames" "$WORK/tsum.out" "trace 7 frames: frame mean"
contains "trace summary's windows" "$WORK/tsum.out" "windows of 3 frames: mean"
contains "trace summary's slowest frames" "$WORK/tsum.out" "slowest 1 % (1 frames,"
printf 'a,b\n1,2\n' > "$WORK/notrace.csv"
"$SRC/tools/rt_bench/trace_summary.sh" "$WORK/notrace.csv" > /dev/null 2> "$WORK/tsum.err"
check "trace summary of a file with no frame column" 1 $?
contains "no frame column named" "$WORK/tsum.err" "trace_summary: no frame / frame_us column"
"$SRC/tools/rt_bench/trace_summary.sh" "$WORK/trace.csv" -3 > /dev/null 2>&1
check "trace summary with a bad window" 2 $?
# shellcheck disable=SC2086
"$BIN" $NODEV --frames 1 --trace "$WORK/no-such-dir/trace.csv" > /dev/null 2> "$WORK/trace.err"
check "--trace to an unwritable path" 1 $?
contains "unwritable trace named" "$WORK/trace.err" "sonocomp: --trace $WORK/no-such-dir/trace.csv: No such file or directory"
# a trace whose rows do not reach the file (a full device) is a runtime error, named
# shellcheck disable=SC2086
"$BIN" $NODEV --frames 3 --trace /dev/full > /dev/null 2> "$WORK/tracefull.err"
check "--trace to a full device" 1 $?
contains "full device named" "$WORK/tracefull.err" "sonocomp: --trace /dev/full: No space left on device"

[ "$fails" = 0 ] && echo "PASS" && exit 0
echo "$fails checks failed"; exit 1
