#!/usr/bin/env bash
# ctest entry point of the HIL tests: skips (exit 77, with the reason) where the VM cannot
# run, builds the static binaries the VM needs (preset "hil"), then runs the named test.
#   tools/hil/ctest-hil.sh display HOST_BUILD_DIR
#   tools/hil/ctest-hil.sh can HOST_BUILD_DIR
#   tools/hil/ctest-hil.sh engine HOST_BUILD_DIR
set -euo pipefail
top=$(cd "$(dirname "$0")/../.." && pwd)
what=${1:?test name}
host_build=${2:?host build dir}
for tool in qemu-system-x86_64 busybox; do
    if ! command -v "$tool" >/dev/null; then
        echo "SKIP: $tool is not installed (tools/install-deps.sh hil installs it)"
        exit 77
    fi
done
"$top/tools/fetch-libccd-source.sh" >/dev/null
"$top/tools/hil/vm.sh" prepare >/dev/null
hil_build="$top/build/hil"
cmake --preset hil -S "$top" >/dev/null
work="$host_build/hil-$what"
case "$what" in
display)
    cmake --build "$hil_build" --target sc-kms-show -j2 >/dev/null
    frame="$host_build/hil-display-frame.raw"
    if [ -f "$host_build/demo-frame.raw" ]; then
        frame="$host_build/demo-frame.raw"
    else
        "$host_build/tools/kms/sc-kms-show" pattern "$frame"
    fi
    exec "$top/tools/hil/display-test.sh" "$hil_build/tools/kms/sc-kms-show" \
        "$host_build/tools/kms/sc-kms-show" "$frame" "$work"
    ;;
can)
    exec "$top/tools/hil/can-test.sh" "$hil_build" "$work"
    ;;
engine)
    exec "$top/tools/hil/engine-can-test.sh" "$hil_build" "$host_build" "$work"
    ;;
*)
    echo "unknown HIL test $what" >&2
    exit 2
    ;;
esac
