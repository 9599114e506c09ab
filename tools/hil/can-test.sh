#!/usr/bin/env bash
# The CAN receive side on real SocketCAN: boots the HIL VM (vcan0, CAN FD MTU), runs the tracker
# emulator into vcan0 with injected faults while sc-tracker-listen drains it through the
# engine's tracker (kernel filters, kernel time stamps) and records a candump -l log, with
# can-utils as independent peers: cansend injects a foreign id and a malformed protocol frame,
# candump -L records the bus on its own. Then both logs are replayed through the tracker.
# Checks on the host: every injected fault counted live, the kernel filter dropped the foreign
# id, every frame had a kernel time stamp, and the replays of our log and of candump's log
# reach the same verdicts as the live run. Classic CAN and CAN FD; the listener runs as nobody.
# Last, can-utils' canplayer plays a log the emulator wrote, and the listener must agree with
# the offline replay of that log.
#   tools/hil/can-test.sh HIL_BUILD_DIR WORKDIR
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: $0 HIL_BUILD_DIR WORKDIR" >&2; exit 2; }
hil_build=$1 work=$2
top=$(cd "$(dirname "$0")/../.." && pwd)
cmake --build "$hil_build" --target sc-tracker-emu sc-tracker-listen -j2 >/dev/null
rm -rf "$work" && mkdir -p "$work/payload"
cp "$hil_build/tools/tracker_emu/sc-tracker-emu" "$hil_build/tools/tracker_emu/sc-tracker-listen" \
   "$work/payload/"
cat > "$work/payload/test.sh" <<'T'
cd /tmp
# the listener runs unprivileged, as the engine does on the appliance
mkdir -p /etc
grep -q '^nobody:' /etc/passwd 2>/dev/null || echo 'nobody:x:65534:65534:nobody:/tmp:/bin/sh' >> /etc/passwd
grep -q '^nogroup:' /etc/group 2>/dev/null || echo 'nogroup:x:65534:' >> /etc/group
chmod 1777 /tmp
chmod 755 / /bin /payload /payload/sc-tracker-listen
ip link set vcan0 down && ip link set vcan0 mtu 72 && ip link set vcan0 up || exit 20
faults="--fault bad-crc:7 --fault repeat:11 --fault implausible:13 --fault counter-jump:97 --fault silence:150"
for mode in classic fd; do
    fdopt=""; [ $mode = fd ] && fdopt="--fd"
    candump -L vcan0 > cd-$mode.log 2>/dev/null &
    cd_pid=$!
    su -s /bin/sh nobody -c "/payload/sc-tracker-listen --iface vcan0 --duration-s 6 --log rx-$mode.log > live-$mode.txt" &
    rx_pid=$!
    sleep 0.5
    /payload/sc-tracker-emu --script sweep --duration-s 4 $fdopt --iface vcan0 $faults 2> emu-$mode.txt || exit 21
    cansend vcan0 555#DEADBEEF || exit 22
    cansend vcan0 100#00 || exit 23
    wait $rx_pid || exit 24
    kill $cd_pid; sleep 0.2
    /payload/sc-tracker-listen --replay rx-$mode.log > own-$mode.txt || exit 25
    /payload/sc-tracker-listen --replay cd-$mode.log > cd-$mode.txt || exit 26
    for f in emu live own cd; do
        tr ' ' '\n' < $f-$mode.txt | grep = | sed "s/^/SCCAN $mode $f /"
    done
    echo "SCCAN $mode candump_lines $(wc -l < cd-$mode.log)"
done
# can-utils' canplayer plays a log the emulator wrote; the listener must reach the same
# verdicts live as the offline replay of that log
/payload/sc-tracker-emu --script rock --duration-s 3 --log emu-play.log $faults 2> emu-play.txt || exit 30
su -s /bin/sh nobody -c "/payload/sc-tracker-listen --iface vcan0 --duration-s 5 > live-play.txt" &
rx_pid=$!
sleep 0.5
canplayer -I emu-play.log || exit 31
wait $rx_pid || exit 32
/payload/sc-tracker-listen --replay emu-play.log > own-play.txt || exit 33
for f in emu live own; do
    tr ' ' '\n' < $f-play.txt | grep = | sed "s/^/SCCAN play $f /"
done
exit 0
T
log="$work/vm-console.log"
rc=0
SC_HIL_LOG="$log" SC_HIL_TIMEOUT_S=${SC_HIL_TIMEOUT_S:-400} "$top/tools/hil/vm.sh" run "$work/payload" || rc=$?
if [ $rc -ne 0 ]; then
    echo "can-test: the VM test failed (rc $rc); console log: $log"
    tail -n 40 "$log"
    exit 1
fi
python3 - "$log" <<'P'
import re, sys
vals = {}
for line in open(sys.argv[1], errors="replace"):
    m = re.search(r"SCCAN (\w+) (\w+) ([\w-]+)=(\d+)", line)
    if m:
        vals[(m.group(1), m.group(2), m.group(3))] = int(m.group(4))
    m = re.search(r"SCCAN (\w+) candump_lines (\d+)", line)
    if m:
        vals[(m.group(1), "cd", "lines")] = int(m.group(2))
fails = []
def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        fails.append(what)
for mode in ("classic", "fd"):
    g = lambda who, k: vals.get((mode, who, k), -1)
    parts = 1 if mode == "fd" else 3
    emu_frames = g("emu", "frames")
    check(emu_frames > 100, "%s: emulator sent %d frames" % (mode, emu_frames))
    if mode == "fd":
        check(g("live", "fd_capable") == 1, "fd: vcan0 with MTU 72 opened as CAN FD")
    check(g("live", "uid") not in (0, -1), "%s: the listener ran unprivileged (uid %d)" % (mode, g("live", "uid")))
    # live: every injected fault counted
    check(g("live", "frames") == emu_frames + 1,
          "%s: listener got every emulator frame plus 100#00 (%d)" % (mode, g("live", "frames")))
    check(g("live", "not_ours") == 0, "%s: kernel filter dropped the foreign id 0x555" % mode)
    check(g("live", "bad_length") == 1, "%s: 100#00 counted as bad length" % mode)
    check(g("live", "e2e_wrong_crc") == g("emu", "bad-crc"),
          "%s: wrong CRC %d == injected %d" % (mode, g("live", "e2e_wrong_crc"), g("emu", "bad-crc")))
    # the emulator's repeat sends a sample twice byte for byte: counted as duplicates, not
    # E2E rejects
    check(g("live", "duplicate") == parts * g("emu", "repeat") and g("live", "e2e_repeated") == 0,
          "%s: duplicates %d == %d x injected %d (E2E repeated %d)"
          % (mode, g("live", "duplicate"), parts, g("emu", "repeat"), g("live", "e2e_repeated")))
    check(g("live", "e2e_wrong_sequence") == parts * g("emu", "counter-jump"),
          "%s: wrong sequence %d == %d x injected %d"
          % (mode, g("live", "e2e_wrong_sequence"), parts, g("emu", "counter-jump")))
    inj = g("emu", "implausible")
    # the speed variant is judged on kernel time stamps: a VM stall of > 33 ms before it
    # could make its jump plausible; the norm and workspace variants are exact
    check(inj * 2 // 3 <= g("live", "rejected_implausible") <= inj,
          "%s: implausible rejected %d of %d injected" % (mode, g("live", "rejected_implausible"), inj))
    check(g("live", "lift_events") >= g("emu", "silence"),
          "%s: lifts %d >= silences %d" % (mode, g("live", "lift_events"), g("emu", "silence")))
    # strict: the kernel stamps every frame (software rx) in order on one CPU, and the node
    # converts them with one held offset (issue #19); a REALTIME step in the VM would be the
    # only excuse for disorder, and is shown
    check(g("live", "ts_missing") == 0 and g("live", "ts_backwards") == 0,
          "%s: every frame had a kernel time stamp, in order (missing %d, backwards %d, "
          "REALTIME steps %d, offset +-%d ns)" % (mode, g("live", "ts_missing"),
          g("live", "ts_backwards"), g("live", "clock_steps"), g("live", "clock_uncertainty_ns")))
    check(g("live", "kernel_drops") == 0, "%s: no kernel drops" % mode)
    # candump saw everything including the foreign id
    check(g("cd", "lines") == emu_frames + 2, "%s: candump -L recorded %d lines" % (mode, g("cd", "lines")))
    check(g("cd", "log_rejected") == 0 and g("own", "log_rejected") == 0,
          "%s: both logs parse without a rejected line" % mode)
    for who in ("own", "cd"):
        for k in ("pose_accepted", "e2e_wrong_crc", "e2e_repeated", "duplicate",
                  "e2e_wrong_sequence", "rejected_implausible", "incomplete", "bad_length"):
            check(g(who, k) == g("live", k), "%s: replay of %s log: %s %d == live %d"
                  % (mode, "our" if who == "own" else "candump's", k, g(who, k), g("live", k)))
    check(g("cd", "not_ours") == 1, "%s: candump's log holds the foreign id" % mode)
g = lambda who, k: vals.get(("play", who, k), -1)
check(g("emu", "frames") > 100 and g("live", "frames") == g("emu", "frames"),
      "canplayer: the listener got all %d frames canplayer played from the emulator's log"
      % g("emu", "frames"))
for k in ("pose_accepted", "e2e_wrong_crc", "e2e_repeated", "duplicate", "e2e_wrong_sequence",
          "rejected_implausible", "incomplete"):
    check(g("live", k) == g("own", k) and g("live", k) >= 0,
          "canplayer: live %s %d == offline replay %d" % (k, g("live", k), g("own", k)))
print("can-test: %s" % ("PASS" if not fails else "FAIL (%d checks)" % len(fails)))
sys.exit(1 if fails else 0)
P
