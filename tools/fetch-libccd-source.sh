#!/usr/bin/env bash
# Unpacks Debian's own libccd source package into third_party/libccd-src for the bare-metal
# build (only src/mpr.c, src/support.c and src/vec3.c are compiled: they never allocate).
# Adds a deb-src entry mirroring the machine's Debian sources if none exists.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
dest="$top/third_party/libccd-src"
if [ -f "$dest/src/mpr.c" ]; then
    exit 0
fi
export DEBIAN_FRONTEND=noninteractive
src_list=/etc/apt/sources.list.d/sonocomp-deb-src.sources
if ! grep -rqs '^Types:.*deb-src' /etc/apt/sources.list.d/ && ! grep -qs '^deb-src' /etc/apt/sources.list; then
    sed 's/^Types: deb$/Types: deb-src/' /etc/apt/sources.list.d/debian.sources > "$src_list"
    apt-get update -q >/dev/null
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
(cd "$work" && apt-get source --download-only -q libccd >/dev/null)
dsc=$(ls "$work"/libccd_*.dsc | head -n 1)
(cd "$work" && dpkg-source --no-check -x "$dsc" unpacked >/dev/null)
mkdir -p "$top/third_party"
rm -rf "$dest"
mv "$work/unpacked" "$dest"
echo "libccd source: $(basename "$dsc") -> $dest"
