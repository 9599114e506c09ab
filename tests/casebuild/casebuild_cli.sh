#!/usr/bin/env bash
# sc-casebuild's command line: every number parsed strictly (the whole string, finite, in
# range), refused with exit status 2 and a message naming the option; nothing hangs.
#   casebuild_cli.sh SC_CASEBUILD CASE.scase WORK_DIR
set -uo pipefail
cb=$1 case=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail=0
# expect STATUS NEEDLE -- ARGS...: exit status and a stderr line holding NEEDLE
expect() {
    local want=$1 needle=$2; shift 3
    timeout 20 "$cb" "$@" > "$work/out" 2> "$work/err"
    local rc=$?
    if [ "$rc" -ne "$want" ] || ! grep -qF -- "$needle" "$work/err"; then
        echo "FAIL: sc-casebuild $*: exit $rc (want $want), stderr: $(head -c 300 "$work/err")" >&2
        fail=1
    fi
}
vol="$work/v.nrrd"
printf 'NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\n' > "$vol"
head -c 64 /dev/zero >> "$vol"
expect 2 "--seed" -- phantom neck-ijv -o "$work/p.scase" --seed abc
expect 2 "--seed" -- phantom neck-ijv -o "$work/p.scase" --seed -1
expect 2 "--spacing" -- phantom neck-ijv -o "$work/p.scase" --spacing -3
expect 2 "--spacing" -- phantom neck-ijv -o "$work/p.scase" --spacing 0.25mm
expect 2 "--spacing" -- import --volume "$vol" -o "$work/i.scase" --spacing 1e-30
expect 2 "--spacing" -- import --volume "$vol" -o "$work/i.scase" --spacing nan
expect 2 "--window" -- import --volume "$vol" -o "$work/i.scase" --window nan:inf
expect 2 "--window" -- import --volume "$vol" -o "$work/i.scase" --window 10:5
expect 2 "--mesh-nodes" -- import --volume "$vol" -o "$work/i.scase" --mesh-nodes -1,2,2
expect 2 "--mesh-nodes" -- import --volume "$vol" -o "$work/i.scase" --mesh-nodes 2,2,2,2
expect 2 "--mesh-nodes" -- import --volume "$vol" -o "$work/i.scase" --mesh-nodes 99,2,2
expect 2 "--mesh-box" -- import --volume "$vol" -o "$work/i.scase" --mesh-box 0,0,0,1,1,inf
expect 2 "--max-voxels" -- import --volume "$vol" -o "$work/i.scase" --max-voxels 0
expect 1 "--depth-axis" -- import --volume "$vol" -o "$work/i.scase" --depth-axis q
expect 1 "vien" -- import --volume "$vol" --labels "$vol" -o "$work/i.scase" --label-map 0=vien
expect 2 "--axis" -- slice "$case" --axis q -o "$work/s.pgm"
expect 2 "--index" -- slice "$case" --index -5 -o "$work/s.pgm"
expect 2 "--iterations" -- isosurface "$case" --label vein --iterations -1 -o "$work/v.ply"
expect 2 "--sigma" -- isosurface "$case" --label vein --sigma -2 -o "$work/v.ply"
expect 2 "--label" -- isosurface "$case" --label veins -o "$work/v.ply"
expect 2 "--repeat" -- bench --repeat 0 "$case"
# the vessel drive options (a DRIV section): the loader's ranges, each refused by name
expect 2 "--heart-rate '19': 0 (none) or 20..250" -- import --volume "$vol" -o "$work/d.scase" --heart-rate 19
expect 2 "--heart-rate" -- import --volume "$vol" -o "$work/d.scase" --heart-rate 251
expect 2 "--heart-rate" -- import --volume "$vol" -o "$work/d.scase" --heart-rate -72
expect 2 "--pulse-kpa" -- import --volume "$vol" -o "$work/d.scase" --pulse-kpa 20.5
expect 2 "--pulse-kpa" -- import --volume "$vol" -o "$work/d.scase" --pulse-kpa nan
expect 2 "--waveform" -- import --volume "$vol" -o "$work/d.scase" --waveform square
expect 2 "--breathing '3'" -- import --volume "$vol" -o "$work/d.scase" --breathing 3
expect 2 "--breathing" -- import --volume "$vol" -o "$work/d.scase" --breathing 61
expect 2 "--venous-swing-kpa" -- import --volume "$vol" -o "$work/d.scase" --venous-swing-kpa 5.1
expect 2 "--valsalva-kpa" -- import --volume "$vol" -o "$work/d.scase" --valsalva-kpa 1e9
expect 2 "--valsalva-kpa" -- reconstruct --sequence "$work/none.igs.mha" -o "$work/d.scase" --valsalva-kpa -1
[ ! -e "$work/d.scase" ] || { echo "FAIL: a refused drive wrote a case" >&2; fail=1; }
# and the good forms still work
"$cb" import --volume "$vol" -o "$work/ok.scase" --mesh-nodes 2,2,2 --window 0:255 > /dev/null || { echo "FAIL: a valid import" >&2; fail=1; }
"$cb" info "$work/ok.scase" | grep -q "labels absent.*vein" || { echo "FAIL: info does not list the absent vein" >&2; fail=1; }
# an imported case with a drive: written as DRIV, loaded and validated by the case loader
# (info, verify) with the values given and the defaults for the rest; without one, no DRIV
"$cb" import --volume "$vol" -o "$work/drive.scase" --mesh-nodes 2,2,2 --heart-rate 84 \
    --pulse-kpa 6.5 --waveform sine --breathing 0 --venous-swing-kpa 0.4 --valsalva-kpa 3 \
    > /dev/null || { echo "FAIL: an import with a drive" >&2; fail=1; }
"$cb" verify "$work/drive.scase" > /dev/null || { echo "FAIL: verify of the case with a drive" >&2; fail=1; }
"$cb" info "$work/drive.scase" > "$work/drive.info" || { echo "FAIL: info of the case with a drive" >&2; fail=1; }
grep -q "vessel drive  *heart 84 / min, pulse 6.5 kPa, sine waveform, breathing 0 / min, venous swing 0.40 kPa, Valsalva 3.0 kPa" \
    "$work/drive.info" || { echo "FAIL: the drive read back: $(grep 'vessel drive' "$work/drive.info")" >&2; fail=1; }
"$cb" import --volume "$vol" -o "$work/hr.scase" --mesh-nodes 2,2,2 --heart-rate 0 > /dev/null &&
    "$cb" info "$work/hr.scase" | grep -q "vessel drive  *heart 0 / min, pulse 5.3 kPa, arterial waveform, breathing 15 / min" ||
    { echo "FAIL: one drive option over the defaults: $("$cb" info "$work/hr.scase" | grep 'vessel drive')" >&2; fail=1; }
"$cb" info "$work/ok.scase" | grep -q "vessel drive  *none" || { echo "FAIL: an import without drive options has a DRIV" >&2; fail=1; }
exit $fail
