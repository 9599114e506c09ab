#!/bin/sh
# tools/cmd-latency.sh [BUILD] [RATE_HZ] [SECONDS] [LOAD]: the console's command latency under a
# tracker stream. Starts the live engine (sc-hostsim --live, neck-ijv, CAN over UDP, state
# stream over UDP) from BUILD (default build/dev: the sanitizer build the browser tests run),
# optionally LOAD busy processes beside it (default 0), then sc-cmd-latency: tracker poses at
# RATE_HZ (default 100) and one signed command every 500 ms for SECONDS (default 20), each
# command's latency to the engine's FRAME record that counts it (p50 / p99 / worst), the
# engine's socket queue; then the engine's own summary (its CAN over UDP lines). HOSTSIM=PATH
# runs another sc-hostsim (e.g. an older build, for a before/after comparison). STALL=E:D stops
# the engine (SIGSTOP) for D seconds every E seconds (default 5:1; 0 none): a host that takes
# the engine's core away now and then, as a loaded host with chromium beside it does.
set -eu
build=${1:-build/dev}
rate=${2:-100}
secs=${3:-20}
load=${4:-0}
out=$(mktemp -d)
trap 'for p in $pids; do kill "$p" 2>/dev/null || true; done; rm -rf "$out"' EXIT INT TERM
pids=""
port() { python3 -c 'import socket; s=socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
can=$(port)
state=$(port)
i=0
while [ "$i" -lt "$load" ]; do
    sh -c 'while :; do :; done' &
    pids="$pids $!"
    i=$((i + 1))
done
"${HOSTSIM:-$build/platform/hostsim/sc-hostsim}" --live --case neck-ijv --cases-dir "$build/cases" \
    --can-udp "$can" --state-udp "127.0.0.1:$state" --seconds $((secs + 30)) --every 0 --quiet \
    --out "$out/engine" >"$out/engine.log" 2>&1 &
engine=$!
pids="$pids $engine"
sleep 1
stall=${STALL:-5:1}
if [ "$stall" != 0 ]; then
    (
        every=${stall%%:*}
        dur=${stall#*:}
        sleep 8 # the case loaded, the first commands answered
        while kill -0 "$engine" 2>/dev/null; do
            sleep "$every"
            kill -STOP "$engine" 2>/dev/null || break
            sleep "$dur"
            kill -CONT "$engine" 2>/dev/null || break
        done
    ) &
    pids="$pids $!"
fi
rc=0
"$build/tools/cmd_latency/sc-cmd-latency" --can-udp "127.0.0.1:$can" --state-port "$state" \
    --rate-hz "$rate" --seconds "$secs" || rc=$?
kill -TERM "$engine" 2>/dev/null || true
wait "$engine" 2>/dev/null || true
grep -E "^live|^can rx|misses|deadline|tracker" "$out/engine.log" || cat "$out/engine.log"
exit "$rc"
