#!/usr/bin/env bash
# End-to-end import: one neck-like labelled volume written by independent tools in every
# format (teem's unu: NRRD in RAS with depth along -j and a foreign label numbering; a
# MetaImage header written by Python, LPS with AnatomicalOrientation, depth +j; pydicom: an
# axial DICOM series, depth along the rows) -> sc-casebuild import with the defaults (depth
# from the file's patient frame, mesh box from the labels, registration of the tracker
# emulator) -> the engine on the host simulator pressing 8 mm at the mesh box's top centre
# (3 s: hover, descend, hold; the press script's deepest point).
# Checks: the three cases have the same label map (the frame was found in each file), and in
# each the vein collapses (min area ratio < 0.5) while the artery holds (> 0.8), running.
#   e2e_import_press.sh SC_CASEBUILD SC_HOSTSIM SOURCE_DIR WORK_DIR
set -euo pipefail
cb=$1 hs=$2 src=$3 work=$4
command -v teem-unu >/dev/null || { echo "e2e: teem-unu missing (tools/install-deps.sh: teem-apps)" >&2; exit 1; }
rm -rf "$work" && mkdir -p "$work"
map=$(/usr/bin/python3 "$src/tests/casebuild/write_e2e_volumes.py" "$work/in")
"$cb" import --volume "$work/in/nrrd/vol.nrrd" --labels "$work/in/nrrd/lab.nrrd" --label-map "$map" -o "$work/nrrd.scase"
# (this one with a vessel drive: a DRIV section the engine loads and applies at the case swap)
"$cb" import --volume "$work/in/mha/vol.mhd" --labels "$work/in/mha/lab.mha" -o "$work/mha.scase" \
    --heart-rate 90 --pulse-kpa 6 --breathing 18 --venous-swing-kpa 0.3 --valsalva-kpa 5
"$cb" import --volume "$work/in/dicom" --labels "$work/in/mha/lab.mha" -o "$work/dicom.scase"
fail=0
"$cb" info "$work/mha.scase" | grep -q "vessel drive  *heart 90 / min, pulse 6.0 kPa, arterial waveform, breathing 18 / min, venous swing 0.30 kPa, Valsalva 5.0 kPa" ||
    { echo "e2e: mha: the drive given to import is not in the case" >&2; fail=1; }
"$cb" info "$work/nrrd.scase" | grep -q "vessel drive  *none" || { echo "e2e: nrrd: a drive nobody asked for" >&2; fail=1; }
ref=""
for f in nrrd mha dicom; do
    "$cb" slice "$work/$f.scase" --axis y --labels -o "$work/$f-labels.pgm"
    sum=$(md5sum < "$work/$f-labels.pgm")
    if [ -z "$ref" ]; then ref=$sum; elif [ "$sum" != "$ref" ]; then
        echo "e2e: $f: label map differs from the NRRD case's (frame or geometry wrong)" >&2; fail=1
    fi
    "$cb" info "$work/$f.scase" | grep -q "labels found.* vein artery" || { echo "e2e: $f: info lacks vein/artery" >&2; fail=1; }
    mkdir -p "$work/out-$f"
    "$hs" --case "$work/$f.scase" --out "$work/out-$f" --every 0 --quiet --seconds 3 > "$work/out-$f/stdout.txt"
    line=$(grep "^compression" "$work/out-$f/summary.txt")
    state=$(grep "^final state" "$work/out-$f/summary.txt")
    vein=$(sed -n 's/.*min vein area ratio \([0-9.]*\) .*/\1/p' <<< "$line")
    artery=$(sed -n 's/.*(artery \([0-9.]*\) there).*/\1/p' <<< "$line")
    echo "$f: vein $vein artery $artery; $state"
    [ -f "$work/out-$f/deepest_compression.png" ] || { echo "e2e: $f: no deepest_compression.png" >&2; fail=1; }
    if [ -z "$vein" ] || [ -z "$artery" ] || ! awk -v v="$vein" -v a="$artery" 'BEGIN { exit !(v < 0.5 && a > 0.8) }'; then
        echo "e2e: $f: want vein < 0.5 and artery > 0.8: $line" >&2; fail=1
    fi
    grep -q "running" <<< "$state" || { echo "e2e: $f: $state" >&2; fail=1; }
done
# A case without a vein label (the segmentation's vein named muscle): info lists the vein as
# absent, the host simulator's summary says so instead of a -1 ratio and still writes the
# deepest press's image.
novein=${map/2=vein/2=muscle}
"$cb" import --volume "$work/in/nrrd/vol.nrrd" --labels "$work/in/nrrd/lab.nrrd" --label-map "$novein" -o "$work/novein.scase" > /dev/null
"$cb" info "$work/novein.scase" | grep -q "labels absent.* vein" || { echo "e2e: novein: info does not list the vein as absent" >&2; fail=1; }
mkdir -p "$work/out-novein"
"$hs" --case "$work/novein.scase" --out "$work/out-novein" --every 0 --quiet --seconds 3 > /dev/null
line=$(grep "^compression" "$work/out-novein/summary.txt")
echo "novein: $line"
grep -q "no vein label in the case; deepest press at frame" <<< "$line" || { echo "e2e: novein: $line" >&2; fail=1; }
grep -q -- "-1" <<< "$line" && { echo "e2e: novein: a -1 ratio in the summary" >&2; fail=1; }
[ -f "$work/out-novein/deepest_compression.png" ] || { echo "e2e: novein: no deepest_compression.png" >&2; fail=1; }
exit $fail
