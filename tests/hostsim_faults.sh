#!/bin/sh
# hostsim_faults.sh HOSTSIM CASES_DIR WORKDIR SCENARIO [CASE METHOD]: fault injection on the host
# simulator's command line (sc-hostsim --faults, platform/hostsim/sc_hs_faults.h), judged from
# its summary and per-frame CSV. Invariants, on the virtual clock with every CAN frame the
# engine takes costing 20 us (--rx-cost-us 20):
#  - no deadline miss in any scenario (the input's volume never shows in the frame time);
#  - every fault is counted once: each episode raises its health fault bit exactly once
#    (bus-off: CAN_BUS_OFF, silence: TRACKER_TIMEOUT, link down: DISPLAY_LINK), a flood raises
#    nothing and every flood frame is counted once at the engine's acceptance filter;
#  - recovery within two frames of the fault clearing (probe tracked again, the fault bit
#    clear, a complete display frame again);
#  - duplicates are counted (each one the bus made from the tracker's frames) but never degrade
#    the engine;
#  - with 50% frame loss, 10% corruption, 10% duplication and 10% reordering for 3 s the engine
#    ends `running`, on every case with both methods (SCENARIO heavy CASE METHOD).
set -u
HOSTSIM=$1
CASES=$2
WORK=$3
SCENARIO=$4
CASE=${5:-neck-ijv}
METHOD=${6:-msds}
OUT="$WORK/$SCENARIO-$CASE-$METHOD"
rm -rf "$OUT" && mkdir -p "$OUT"
fails=0
ok() { echo "ok: $1"; }
bad() { echo "FAIL: $1"; fails=$((fails + 1)); }
expect() { # expect DESCRIPTION CONDITION-STATUS
    if [ "$2" = 0 ]; then ok "$1"; else bad "$1"; fi
}
run() {
    "$HOSTSIM" --cases-dir "$CASES" --case "$CASE" --method "$METHOD" --out "$OUT" --every 0 \
        --quiet --rx-cost-us 20 "$@" > "$OUT/summary.out" 2> "$OUT/stderr"
    rc=$?
    [ $rc = 0 ] || { bad "sc-hostsim exit $rc"; cat "$OUT/stderr"; }
    sed -n '/^tracker\|^health\|^bus faults\|^deadline\|^episode\|^final\|^silence/p' "$OUT/summary.out"
}
S="$OUT/summary.out"
episode() { # episode KIND: its summary line
    grep "^episode $1 " "$S"
}
num() { # num TEXT-BEFORE LINE: the number after TEXT-BEFORE in LINE
    echo "$2" | sed -n "s/.*$1 \(-\?[0-9][0-9]*\).*/\1/p"
}
grep_q() { grep -q -- "$1" "$2"; echo $?; }

case "$SCENARIO" in
episodes)
    run --seconds 6 --faults busoff=1:0.5,silence=2:0.3,flood=3:1,linkdown=4.2:0.4
    for k in busoff silence linkdown; do
        l=$(episode "$k")
        [ "$(num 'raised' "$l")" = 1 ]; expect "$k: its fault raised exactly once ($l)" $?
        r=$(num 'recovered' "$l")
        [ "$r" -ge 1 ] && [ "$r" -le 2 ]; expect "$k: recovered $r frames after it cleared (<= 2)" $?
    done
    l=$(episode flood)
    [ "$(num 'raised' "$l")" = 0 ]; expect "flood: no tracker fault raised" $?
    inj=$(echo "$l" | sed -n 's/.*injected \([0-9]*\).*/\1/p')
    fil=$(echo "$l" | sed -n 's/.*filtered \([0-9]*\).*/\1/p')
    [ "$inj" = 4504 ]; expect "flood: 1 s at 500 kbit/s = 4504 foreign frames sent ($inj)" $?
    [ "$fil" = "$inj" ]; expect "flood: every foreign frame counted once at the engine's filter ($fil)" $?
    echo "$l" | grep -q ", 0 untracked frames"; expect "flood: the probe stayed tracked" $?
    grep -q "^silence  *90 tracker frames not sent" "$S"; expect "silence: 0.3 s of tracker frames withheld" $?
    grep -q "^health .*bus-off 1, display link 1" "$S"; expect "health: one bus-off, one link-down raise" $?
    grep -q "2 error frames" "$S"; expect "bus: one bus-off and one restart error frame" $?
    grep -q "lift events" "$S" && grep -q ", 2 lift events" "$S"; expect "tracker: two lifts (bus-off, silence)" $?
    ;;
duplicates)
    run --seconds 4 --faults dup=200000
    l=$(grep "^tracker dups" "$S")
    d=$(echo "$l" | sed -n 's/^tracker dups *\([0-9]*\) duplicates.*/\1/p')
    b=$(echo "$l" | sed -n 's/.* of \([0-9]*\) the bus duplicated.*/\1/p')
    [ "$d" -gt 50 ] && [ "$d" = "$b" ]; expect "duplicates: $d counted of $b made by the bus" $?
    grep -q "^tracker .* 0 E2E rejects" "$S"; expect "duplicates: no E2E reject" $?
    n=$(awk -F, 'NR > 1 && $7 != "running"' "$OUT/frames.csv" | wc -l)
    [ "$n" = 0 ]; expect "duplicates: running in every frame ($n frames not)" $?
    grep -q "^health .*tracker data 0," "$S"; expect "duplicates: no tracker-data fault" $?
    ;;
heavy)
    run --seconds 5 --faults drop=500000,corrupt=100000,dup=100000,reorder=100000,random=0.5:3.5
    grep -q "^final state *running," "$S"; expect "$CASE $METHOD: ends running" $?
    grep -q "^method *$METHOD" "$S"; expect "$CASE $METHOD: ran $METHOD" $?
    l=$(episode random)
    r=$(num 'recovered' "$l")
    [ "$r" -ge 1 ] && [ "$r" -le 2 ]; expect "$CASE $METHOD: tracked again $r frames after the faults stopped" $?
    grep -q "^tracker .* [1-9][0-9]* E2E rejects" "$S"; expect "$CASE $METHOD: the corruption was seen (E2E rejects)" $?
    ;;
*)
    echo "unknown scenario $SCENARIO"; exit 2 ;;
esac
grep -q "^deadline *0 misses" "$S"; expect "no deadline miss on the virtual clock" $?
[ "$fails" = 0 ] && echo "PASS" && exit 0
echo "$fails checks failed"; exit 1
