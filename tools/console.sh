#!/usr/bin/env bash
# The instructor console on this host, in one command: builds (release preset by default), then
# runs the engine on the host simulator in live mode (sc-hostsim --live: frames released at
# wall-clock time, the deadline on the virtual clock; CAN over UDP because a development host
# has no SocketCAN), the console gateway, and prints the console's URL. Ctrl-C stops both.
#   tools/console.sh [--preset dev|release] [--port 8080] [--case neck-ijv] [--pass PHRASE]
# Press the probe from another shell with the command it prints. Recorded sessions (bundles,
# docs/session-bundle.md) in out/console/sessions are listed on the console and replayed there;
# record one with the command it prints (sc-hostsim --record-bundle).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
preset=release port=8080 case=neck-ijv pass=()
while [ $# -gt 0 ]; do
    case "$1" in
    --preset) preset=$2; shift 2 ;;
    --port) port=$2; shift 2 ;;
    --case) case=$2; shift 2 ;;
    --pass) pass=(--pass "$2"); shift 2 ;;
    *) echo "usage: $0 [--preset dev|release] [--port N] [--case NAME] [--pass PHRASE]" >&2; exit 2 ;;
    esac
done
if [ "$(id -u)" -eq 0 ]; then
    "$top/tools/install-deps.sh" base
fi
cd "$top"
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" -j2 --target sc-hostsim sc-gateway sc-tracker-emu console cases >/dev/null
b=$top/build/$preset
can=47000 state=47001 dlink=47002
sessions=$top/out/console/sessions
mkdir -p "$top/out/console" "$sessions"
"$b/platform/hostsim/sc-hostsim" --live --case "$case" --cases-dir "$b/cases" --can-udp $can \
    --state-udp 127.0.0.1:$state --dlink-udp 127.0.0.1:$dlink --seconds 3600 --every 0 --quiet \
    --out "$top/out/console" > "$top/out/console/engine.txt" 2>&1 &
engine=$!
"$b/tools/gateway/sc-gateway" --port "$port" --www "$b/console" --state-port $state \
    --dlink-port $dlink --can-udp 127.0.0.1:$can --cases-dir "$b/cases" "${pass[@]}" \
    --sessions "$sessions" --hostsim "$b/platform/hostsim/sc-hostsim" \
    > "$top/out/console/gateway.txt" 2>&1 &
gateway=$!
trap 'kill $gateway $engine 2>/dev/null; wait $gateway $engine 2>/dev/null; tail -n 4 "$top/out/console/engine.txt"' EXIT INT TERM
sleep 1
kill -0 $gateway 2>/dev/null || { cat "$top/out/console/gateway.txt"; exit 1; }
echo "console: http://$(hostname -I 2>/dev/null | awk '{print $1}' || echo 127.0.0.1):$port/  (also http://127.0.0.1:$port/)"
echo "press the probe: $b/tools/tracker_emu/sc-tracker-emu --script press --udp 127.0.0.1:$can --duration-s 20"
echo "record a session for the console's Sessions panel: $b/platform/hostsim/sc-hostsim --case $case --cases-dir $b/cases --script press --seconds 10 --every 0 --record-bundle $sessions/press-\$(date +%Y%m%d-%H%M%S).scb"
echo "engine and gateway logs in out/console/; Ctrl-C stops"
wait $engine
