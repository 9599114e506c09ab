#!/usr/bin/env bash
# The engine's main job on the host simulator: builds the release preset, generates the
# phantom cases, then runs sc-hostsim on the default case (neck-ijv) with a scripted probe
# compression and release. B-scans (PNG), frames.csv and summary.txt land in out/demo/.
# Extra arguments go to sc-hostsim (e.g. --case femoral-dvt --method fem --script sweep).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"
tools/install-deps.sh base
cmake --preset release >/dev/null
cmake --build --preset release -j"$(nproc)" --target sc-hostsim cases
rm -rf out/demo
build/release/platform/hostsim/sc-hostsim --out out/demo --depth 12 --quiet "$@"
echo "B-scans and summary written to $top/out/demo/"
