#!/usr/bin/env bash
# Writes docs/images/strip-<case>.png: what the engine shows for each phantom case, side by
# side: at rest (the first frame in contact), pressed 16 mm (the deepest compression of the press
# script), and rocked 15 degrees (the rock script at its largest angle), on the host simulator
# (deterministic, MSDS). The neck is shown three times: acoustics and speckle baked into its
# voxels (the default case); acoustics computed by the engine along the beam (sc-casebuild
# phantom --acoustics engine); and both acoustics and speckle from the engine (--speckle engine:
# the scatterer field convolved with the beam's PSF, core/imaging/sc_psf.h).
# Needs a Release build: cmake --preset release && cmake --build build/release --target
# sc-hostsim cases sc-casebuild. Run from the repository's top.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
bin=$top/build/release
hs=$bin/platform/hostsim/sc-hostsim
cb=$bin/tools/casebuild/sc-casebuild
out=$top/docs/images
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"
"$cb" phantom neck-ijv --acoustics engine -o "$work/neck-ijv-engine-acoustics.scase"
"$cb" phantom neck-ijv --acoustics engine --speckle engine -o "$work/neck-ijv-engine-speckle.scase"

shoot() { # case-name-or-path tag
    local c=$1 tag=$2
    "$hs" --case "$c" --script press --depth 16 --seconds 2.5 --every 1 --out "$work/$tag-press" \
        --quiet >/dev/null
    "$hs" --case "$c" --script rock --depth 8 --seconds 1.05 --every 1 --out "$work/$tag-rock" \
        --quiet >/dev/null
    local first
    first=$(awk -F, 'NR > 1 && $4 == 1 { print $1; exit }' "$work/$tag-press/frames.csv")
    /usr/bin/python3 - "$work" "$tag" "$first" "$out/strip-$tag.png" <<'EOF'
import sys
from PIL import Image, ImageDraw
work, tag, first, dest = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
shots = [("rest", f"{work}/{tag}-press/frame_{first:05d}.png"),
         ("press 16 mm", f"{work}/{tag}-press/deepest_compression.png"),
         ("rocked 15 deg", f"{work}/{tag}-rock/frame_00060.png")]
imgs = [Image.open(p).convert("L") for _, p in shots]
w, h = imgs[0].size
strip = Image.new("L", (3 * w + 20, h + 24), 0)
d = ImageDraw.Draw(strip)
for i, ((name, _), im) in enumerate(zip(shots, imgs)):
    strip.paste(im, (i * (w + 10), 24))
    d.text((i * (w + 10) + 4, 6), f"{tag}: {name}", fill=255)
strip = strip.resize((strip.width // 2, strip.height // 2), Image.LANCZOS)
strip.save(dest, optimize=True)
EOF
    echo "$out/strip-$tag.png"
}

for c in neck-ijv femoral femoral-dvt; do
    shoot "$c" "$c"
done
shoot "$work/neck-ijv-engine-acoustics.scase" neck-ijv-engine-acoustics
shoot "$work/neck-ijv-engine-speckle.scase" neck-ijv-engine-speckle
