#!/usr/bin/env bash
# The cross builds: the Cortex-M7 bare-metal image (prints its RAM and flash use) and the
# aarch64 build whose unit tests run under qemu-aarch64-static.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"
tools/install-deps.sh cross
tools/fetch-libccd-source.sh
cmake --preset cortex-m7
cmake --build --preset cortex-m7
cmake --preset aarch64
cmake --build --preset aarch64 -j"$(nproc)"
ctest --preset aarch64
