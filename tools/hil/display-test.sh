#!/usr/bin/env bash
# The engine's panel sinks on a real KMS device: boots the HIL VM with qemu's standard VGA
# (the kernel's bochs DRM driver), shows FRAME through the DRM/KMS sink and then through the
# fbdev sink, takes a qemu screendump of each, and compares every pixel on the host with the
# same frame scan-converted at the panel's mode.
#   tools/hil/display-test.sh SC_KMS_SHOW_STATIC HOST_SC_KMS_SHOW FRAME WORKDIR
set -euo pipefail
[ $# -eq 4 ] || { echo "usage: $0 STATIC_SC_KMS_SHOW HOST_SC_KMS_SHOW FRAME WORKDIR" >&2; exit 2; }
static_bin=$1 host_bin=$2 frame=$3 work=$4
top=$(cd "$(dirname "$0")/../.." && pwd)
rm -rf "$work" && mkdir -p "$work/payload"
cp "$static_bin" "$work/payload/sc-kms-show"
cp "$frame" "$work/payload/frame.raw"
touch "$work/payload/want-display"
cat > "$work/payload/test.sh" <<'T'
./sc-kms-show show frame.raw --hold-s 6 || exit 10
./sc-kms-show show frame.raw --fbdev --hold-s 6 || exit 11
T
mon="$work/monitor.sock"
log="$work/vm-console.log"
SC_HIL_MONITOR="$mon" SC_HIL_LOG="$log" "$top/tools/hil/vm.sh" run "$work/payload" &
vm=$!
dump() { # kind file
    local t=0
    until grep -q "SC_KMS_READY kind=$1" "$log" 2>/dev/null; do
        sleep 0.5
        t=$((t + 1))
        if [ $t -gt 400 ] || ! kill -0 "$vm" 2>/dev/null; then
            echo "display-test: the VM never showed the $1 frame" >&2
            return 1
        fi
    done
    sleep 1
    python3 - "$mon" "$2" <<'P'
import socket, sys, time
s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
s.connect(sys.argv[1])
s.settimeout(5)
time.sleep(0.2)
s.recv(4096)
s.sendall(("screendump %s\n" % sys.argv[2]).encode())
time.sleep(1.5)
s.close()
P
    [ -s "$2" ] || { echo "display-test: no screendump for $1" >&2; return 1; }
}
rc=0
dump drm "$work/drm.ppm" || rc=1
dump fbdev "$work/fbdev.ppm" || rc=1
wait "$vm" || rc=1
grep "SC_KMS_READY" "$log" || true
if [ $rc -eq 0 ]; then
    echo "drm sink:"; "$host_bin" compare "$frame" "$work/drm.ppm" || rc=1
    echo "fbdev sink:"; "$host_bin" compare "$frame" "$work/fbdev.ppm" || rc=1
fi
[ $rc -eq 0 ] && echo "display-test: PASS" || echo "display-test: FAIL (console log: $log)"
exit $rc
