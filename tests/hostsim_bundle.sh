#!/bin/sh
# hostsim_bundle.sh HOSTSIM CASES_DIR WORKDIR SCENARIO: session bundles on sc-hostsim's command
# line (platform/linux/sc_bundle.h, docs/session-bundle.md).
#  replay    a press on femoral-dvt with the call DVT and 2% frame loss, recorded as a bundle
#            (FEM), then `--replay BUNDLE` with no other argument: the same method, length and
#            score, and every frame's image hash identical to the recording's frames.csv;
#            `--list-bundles` shows it as JSON with its case, method, frames and score;
#  refuse    a bundle whose case is missing, or whose case file by that name has other
#            content (another case copied under its name), or given with another --case: each
#            refused by name with exit 1 before any frame runs; a truncated bundle, one with a
#            flipped image hash, one with bytes appended, and a candump log passed off as a
#            bundle: refused with their reason; `--list-bundles` counts the refused ones.
set -u
HOSTSIM=$1
CASES=$2
WORK=$3
SCENARIO=$4
OUT="$WORK/$SCENARIO"
rm -rf "$OUT" && mkdir -p "$OUT"
fails=0
ok() { echo "ok: $1"; }
bad() { echo "FAIL: $1"; fails=$((fails + 1)); }
expect() { if [ "$2" = 0 ]; then ok "$1"; else bad "$1"; fi; }
B="$OUT/session.scb"

record() {
    "$HOSTSIM" --cases-dir "$CASES" --case femoral-dvt --method fem --seconds 3 --depth 14 \
        --every 0 --quiet --faults drop=20000 --call dvt@2.5 --out "$OUT/rec" \
        --record-bundle "$B" > "$OUT/rec.out" 2> "$OUT/rec.err"
    rc=$?
    [ $rc = 0 ] || { bad "recording exit $rc"; cat "$OUT/rec.err"; exit 1; }
}

case $SCENARIO in
replay)
    record
    grep '^assessment\|^bundle' "$OUT/rec.out"
    "$HOSTSIM" --cases-dir "$CASES" --replay "$B" --every 0 --quiet --out "$OUT/rep" \
        > "$OUT/rep.out" 2> "$OUT/rep.err"
    rc=$?
    expect "replay of the bundle alone exits 0 (rc $rc)" $([ $rc = 0 ]; echo $?)
    grep '^method\|^assessment\|^bundle replay' "$OUT/rep.out"
    grep -q '^method          fem' "$OUT/rep.out"
    expect "the replay runs the bundle's method (fem)" $?
    grep -q 'every image hash identical' "$OUT/rep.out"
    expect "the replay says every image hash is identical" $?
    n_rec=$(($(wc -l < "$OUT/rec/frames.csv") - 1))
    n_rep=$(($(wc -l < "$OUT/rep/frames.csv") - 1))
    expect "as many frames replayed as recorded ($n_rep of $n_rec)" $([ "$n_rec" = "$n_rep" ] && [ "$n_rec" -gt 100 ]; echo $?)
    cut -d, -f1,9 "$OUT/rec/frames.csv" > "$OUT/rec.hashes"
    cut -d, -f1,9 "$OUT/rep/frames.csv" > "$OUT/rep.hashes"
    cmp -s "$OUT/rec.hashes" "$OUT/rep.hashes"
    expect "per-frame image hashes of the replay identical to the recording's" $?
    distinct=$(cut -d, -f2 "$OUT/rec.hashes" | sort -u | wc -l)
    expect "the session's images change ($distinct distinct hashes)" $([ "$distinct" -gt 20 ]; echo $?)
    s_rec=$(sed -n 's/^assessment *score \([0-9]*\/[0-9]*\).*/\1/p' "$OUT/rec.out")
    s_rep=$(sed -n 's/^assessment *score \([0-9]*\/[0-9]*\).*/\1/p' "$OUT/rep.out")
    expect "the replay's score equals the recording's ($s_rep, $s_rec)" $([ -n "$s_rec" ] && [ "$s_rec" = "$s_rep" ]; echo $?)
    grep -q 'call dvt, finding dvt' "$OUT/rep.out"
    expect "the call DVT came through the bundle's CAN log" $?
    # the solver's budget is not recorded in a bundle: refused with one, used without one
    "$HOSTSIM" --cases-dir "$CASES" --replay "$B" --cg-iterations 8 --every 0 --quiet \
        --out "$OUT/rep8" > /dev/null 2> "$OUT/rep8.err"
    rc=$?
    expect "--cg-iterations with a bundle replay refused, exit 2 (rc $rc)" $([ $rc = 2 ]; echo $?)
    grep -q 'does not record --cg-iterations' "$OUT/rep8.err"
    expect "the refusal says why" $?
    "$HOSTSIM" --cases-dir "$CASES" --case femoral-dvt --method fem --seconds 3 --depth 14 \
        --every 0 --quiet --cg-iterations 8 --record-bundle "$OUT/cg8.scb" --out "$OUT/cg8" \
        > /dev/null 2>&1
    rc=$?
    expect "--cg-iterations with --record-bundle refused, exit 2 (rc $rc)" $([ $rc = 2 ]; echo $?)
    "$HOSTSIM" --cases-dir "$CASES" --case femoral-dvt --method fem --seconds 3 --depth 14 \
        --every 0 --quiet --faults drop=20000 --cg-iterations 3 --out "$OUT/cg3" \
        > "$OUT/cg3.out" 2>&1
    rc=$?
    expect "a run with --cg-iterations 3 exits 0 (rc $rc)" $([ $rc = 0 ]; echo $?)
    grep -q '^method          fem, 3 CG iterations per frame' "$OUT/cg3/summary.txt"
    expect "its summary names the budget" $?
    grep -q '^method          fem, 10 CG iterations per frame' "$OUT/rep/summary.txt"
    expect "the default budget in the replay's summary" $?
    cut -d, -f1,9 "$OUT/cg3/frames.csv" > "$OUT/cg3.hashes"
    cmp -s "$OUT/rec.hashes" "$OUT/cg3.hashes"
    expect "3 CG iterations give other images than 10" $([ $? != 0 ]; echo $?)
    grep -q '^call dvt$' "$B" && grep -q '^finding dvt$' "$B"
    expect "the bundle's header holds the call and the finding" $?
    "$HOSTSIM" --list-bundles "$OUT" > "$OUT/list.json"
    cat "$OUT/list.json"
    if [ -x /usr/bin/python3 ]; then
        /usr/bin/python3 - "$OUT/list.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
b = d["bundles"][0]
assert d["count"] == 1 and d["refused"] == 0, d
assert b["file"] == "session.scb" and b["case"] == "femoral-dvt.scase", b
assert b["method"] == "fem" and b["frames"] > 100 and b["call"] == "dvt", b
assert 0 < b["score"] <= b["score_max"], b
PY
        expect "--list-bundles prints valid JSON with case, method, frames and score" $?
    else
        grep -q '"case": "femoral-dvt.scase"' "$OUT/list.json"
        expect "--list-bundles names the case" $?
    fi
    ;;
refuse)
    record
    refused() { # refused DESCRIPTION PATTERN ARGS...: exit 1, message matching PATTERN
        d=$1; p=$2; shift 2
        "$HOSTSIM" --every 0 --quiet --out "$OUT/ref" "$@" > "$OUT/ref.out" 2> "$OUT/ref.err"
        rc=$?
        msg=$(cat "$OUT/ref.err")
        echo "  $d: exit $rc: $msg"
        [ $rc = 1 ] && grep -q "$p" "$OUT/ref.err" && [ ! -s "$OUT/ref/frames.csv" ]
        expect "$d" $?
        rm -rf "$OUT/ref"
    }
    mkdir -p "$OUT/empty" "$OUT/other"
    refused "a bundle whose case is missing is refused by name" \
        "the bundle's case 'femoral-dvt.scase' is not in" --cases-dir "$OUT/empty" --replay "$B"
    cp "$CASES/femoral.scase" "$OUT/other/femoral-dvt.scase"
    refused "a bundle whose case file has other content is refused" \
        "case 'femoral-dvt.scase' in .* is not the bundle's" --cases-dir "$OUT/other" --replay "$B"
    refused "a bundle replayed with another --case is refused" \
        "recorded on case 'femoral-dvt.scase'; --case 'neck-ijv' is another case" \
        --cases-dir "$CASES" --case neck-ijv --replay "$B"
    head -c $(($(wc -c < "$B") / 2)) "$B" > "$OUT/trunc.scb"
    refused "a truncated bundle is refused" "bundle refused: truncated" \
        --cases-dir "$CASES" --replay "$OUT/trunc.scb"
    awk '/^hashes /{h=1; print; next} h==1 && $1=="10" {sub(/.$/, ($2 ~ /0$/) ? "1" : "0")} {print}' \
        "$B" > "$OUT/flip.scb"
    cmp -s "$B" "$OUT/flip.scb" && bad "the flipped copy differs"
    refused "a bundle with one image hash changed is refused (checksum)" \
        "bundle refused: checksum mismatch" --cases-dir "$CASES" --replay "$OUT/flip.scb"
    { cat "$B"; echo "extra"; } > "$OUT/tail.scb"
    refused "a bundle with bytes after its end line is refused" \
        "bundle refused: bytes after the end line" --cases-dir "$CASES" --replay "$OUT/tail.scb"
    { echo "SCBUNDLE 1"; sed -n '/^can /,/^events /p' "$B" | sed '1d;$d'; } > "$OUT/log.scb"
    refused "a candump log under a bundle header is refused" "bundle refused: bad header field" \
        --cases-dir "$CASES" --replay "$OUT/log.scb"
    "$HOSTSIM" --list-bundles "$OUT" > "$OUT/list.json"
    grep -q '"count": 5, "refused": 4' "$OUT/list.json"
    expect "--list-bundles lists 5 bundles and counts the 4 refused ones" $?
    ;;
*)
    echo "unknown scenario $SCENARIO"; exit 2 ;;
esac
echo "$fails failure(s)"
[ $fails = 0 ]
