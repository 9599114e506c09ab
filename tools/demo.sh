#!/usr/bin/env bash
# The engine's main job: builds the release preset and the phantom cases, then
#  1. runs sc-hostsim: the core on the host simulator (virtual clock, simulated CAN bus) on the
#     default case (neck-ijv) with a scripted probe compression and release; B-scans (PNG),
#     frames.csv and summary.txt land in out/demo/ (deterministic: same run, same hashes);
#  2. runs the real loop (tools/demo-live.sh): the tracker emulator's CAN log replayed in real
#     time into the `sonocomp` binary (this host's kernel has no SocketCAN), its scan lines over
#     the UDP display link to `sc-viewer`, which records the frames; out/demo/live/.
# Extra arguments go to sc-hostsim (e.g. --case femoral-dvt --method fem --script sweep).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"
tools/install-deps.sh base
cmake --preset release >/dev/null
cmake --build --preset release -j"$(nproc)" --target sc-hostsim cases sonocomp sc-tracker-emu \
    sc-viewer
rm -rf out/demo
build/release/platform/hostsim/sc-hostsim --out out/demo --depth 8 --quiet "$@"
tools/demo-live.sh build/release out/demo
echo "B-scans and summaries written to $top/out/demo/ (host simulator) and $top/out/demo/live/ (real loop)"
