#!/usr/bin/env bash
# Installs the Debian packages a task needs, as root, on Debian 12. Idempotent and quick when
# everything is present (no apt-get update then).
#   tools/install-deps.sh base      build + tests on the host (default)
#   tools/install-deps.sh cross     cortex-m7 (arm-none-eabi, newlib) and aarch64 (qemu-user)
#   tools/install-deps.sh hil       the SocketCAN/KMS VM bench (qemu-system, busybox, kernel)
#   tools/install-deps.sh fuzz      the fuzz preset (clang 14 with libFuzzer and its sanitizers)
set -euo pipefail

base=(build-essential cmake pkg-config libccd-dev libcmocka-dev libpng-dev zlib1g-dev libgif-dev
      libdrm-dev
      python3-pydicom python3-numpy
      libdcmtk-dev libteem-dev teem-apps libmbedtls-dev
      python3 python3-canmatrix libsdl2-dev xvfb xauth can-utils
      libwebsockets-dev chromium
      libbullet-dev)
cross=(gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi
       gcc-aarch64-linux-gnu qemu-user-static dpkg-dev)
cross_arm64=(libcmocka-dev:arm64 libccd-dev:arm64 zlib1g-dev:arm64 libpng-dev:arm64
             libgif-dev:arm64 libmbedtls-dev:arm64)
hil=(qemu-system-x86 busybox-static can-utils)
fuzz=(clang clang-14 libclang-rt-14-dev llvm-14)

if [ "$(id -u)" -ne 0 ]; then
    echo "install-deps: run as root (apt-get needs it)" >&2
    exit 2
fi
export DEBIAN_FRONTEND=noninteractive

missing() {
    local out=()
    for p in "$@"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || out+=("$p")
    done
    echo "${out[@]:-}"
}

updated=0
apt_install() {
    local need
    need=$(missing "$@")
    [ -z "$need" ] && return 0
    if [ "$updated" -eq 0 ]; then
        apt-get update -q >/dev/null
        updated=1
    fi
    # shellcheck disable=SC2086
    apt-get install -y -q --no-install-recommends $need >/dev/null
}

# The console page and its browser tests: node and npm (Debian's, unless a node is already
# installed: nodesource's nodejs carries its own npm and conflicts with Debian's npm package),
# then the page's npm packages (three, playwright-core) exactly as package-lock.json pins them.
console_npm() {
    if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
        apt_install nodejs npm
    fi
    local dir
    dir=$(cd "$(dirname "$0")/console" && pwd)
    if [ ! -d "$dir/node_modules/three" ] || [ ! -d "$dir/node_modules/playwright-core" ] ||
       [ "$dir/package-lock.json" -nt "$dir/node_modules/.package-lock.json" ]; then
        (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
    fi
}

want=${1:-base}
case "$want" in
base)
    apt_install "${base[@]}"
    console_npm
    ;;
cross)
    apt_install "${base[@]}"
    if ! dpkg --print-foreign-architectures | grep -qx arm64; then
        dpkg --add-architecture arm64
        updated=0
    fi
    apt_install "${cross[@]}" "${cross_arm64[@]}"
    ;;
hil)
    apt_install "${base[@]}" "${hil[@]}"
    ;;
fuzz)
    apt_install "${base[@]}" "${fuzz[@]}"
    ;;
*)
    echo "usage: $0 [base|cross|hil|fuzz]" >&2
    exit 2
    ;;
esac
