#!/usr/bin/env bash
# Builds the dev preset (Debug, ASan + UBSan, invariant checks, -Werror) and runs every host
# test with ctest. Installs the Debian packages it needs first (as root).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"
tools/install-deps.sh base
tools/install-deps.sh hil
cmake --preset dev
cmake --build --preset dev -j"$(nproc)"
ctest --preset dev
