#!/usr/bin/env bash
# A small Linux VM with real SocketCAN (vcan) and a KMS display, for hardware-in-loop tests on
# machines whose own kernel has no CAN (see shared/notes/vcan-vm.md).
#
#   tools/hil/vm.sh prepare            fetch Debian's kernel package, unpack kernel + modules
#   tools/hil/vm.sh run PAYLOAD_DIR    boot the VM with PAYLOAD_DIR at /payload and run
#                                      /payload/test.sh inside; exit with its status
# Environment: SC_HIL_CACHE (kernel cache, default build/hil-cache), SC_HIL_TIMEOUT_S (300),
#   SC_HIL_LOG (serial console log, default PAYLOAD_DIR/../vm-console.log),
#   SC_HIL_MONITOR (a unix socket path for qemu's monitor, e.g. to take screendumps),
#   SC_HIL_QEMU_ARGS (extra qemu arguments).
# The VM runs under TCG (a KVM boot hung here); it powers itself off after the test, and the
# host side greps the console for the result line, with a timeout.
set -euo pipefail
top=$(cd "$(dirname "$0")/../.." && pwd)
cache=${SC_HIL_CACHE:-$top/build/hil-cache}
timeout_s=${SC_HIL_TIMEOUT_S:-300}

die() { echo "hil: $*" >&2; exit 2; }

kernel_pkg() {
    apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ {print $2; exit}'
}

prepare() {
    if [ -f "$cache/ok" ]; then
        return 0
    fi
    command -v qemu-system-x86_64 >/dev/null || die "qemu-system-x86_64 missing (tools/install-deps.sh hil)"
    command -v busybox >/dev/null || die "busybox missing (tools/install-deps.sh hil)"
    local pkg
    pkg=$(kernel_pkg)
    [ -n "$pkg" ] || { apt-get update -q >/dev/null; pkg=$(kernel_pkg); }
    [ -n "$pkg" ] || die "cannot find Debian's kernel package name"
    rm -rf "$cache"
    mkdir -p "$cache/dl"
    chmod 777 "$cache/dl"
    (cd "$cache/dl" && apt-get download -q "$pkg" >/dev/null 2>&1) || die "apt-get download $pkg failed"
    dpkg -x "$cache"/dl/*.deb "$cache/root"
    rm -rf "$cache/dl"
    local kver
    kver=$(ls "$cache/root/lib/modules" | head -n 1)
    echo "$kver" > "$cache/kver"
    cp "$cache/root/boot/vmlinuz-$kver" "$cache/vmlinuz"
    touch "$cache/ok"
    echo "hil: kernel $kver ready in $cache"
}

# copy a dynamically linked program and the libraries it needs into the initramfs tree
copy_dyn() {
    local bin=$1 dest=$2
    install -D -m 0755 "$bin" "$dest/bin/$(basename "$bin")"
    ldd "$bin" 2>/dev/null | awk '/=> \// {print $3} /^\t\/lib/ {print $1}' | while read -r lib; do
        [ -f "$lib" ] && install -D -m 0755 "$lib" "$dest$lib"
    done
}

run() {
    local payload=$1
    [ -f "$payload/test.sh" ] || die "$payload/test.sh missing"
    prepare
    local kver mods tree log
    kver=$(cat "$cache/kver")
    mods="$cache/root/lib/modules/$kver/kernel"
    tree=$(mktemp -d)
    trap 'rm -rf "$tree"' RETURN
    mkdir -p "$tree"/{bin,sbin,proc,sys,dev,tmp,lib/modules,payload,lib64,usr/lib}
    cp "$(command -v busybox)" "$tree/bin/busybox"
    for m in net/can/can.ko net/can/can-raw.ko drivers/net/can/dev/can-dev.ko drivers/net/can/vcan.ko \
             drivers/gpu/drm/drm.ko drivers/gpu/drm/drm_kms_helper.ko drivers/gpu/drm/ttm/ttm.ko \
             drivers/gpu/drm/drm_ttm_helper.ko drivers/gpu/drm/drm_vram_helper.ko drivers/gpu/drm/tiny/bochs.ko; do
        [ -f "$mods/$m" ] && cp "$mods/$m" "$tree/lib/modules/"
    done
    for tool in candump cansend canplayer cangen; do
        command -v "$tool" >/dev/null && copy_dyn "$(command -v "$tool")" "$tree"
    done
    cp -a "$payload/." "$tree/payload/"
    cat > "$tree/init" <<'INIT'
#!/bin/busybox sh
/bin/busybox --install -s /bin
export PATH=/bin:/sbin
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev
mount -t tmpfs tmp /tmp
for m in can can-raw can-dev vcan; do insmod /lib/modules/$m.ko || echo "hil: insmod $m failed"; done
if [ -f /payload/want-display ]; then
    for m in drm drm_kms_helper ttm drm_ttm_helper drm_vram_helper bochs; do
        insmod /lib/modules/$m.ko 2>/dev/null || echo "hil: insmod $m failed"
    done
fi
ip link add dev vcan0 type vcan && ip link set vcan0 up || echo "hil: vcan0 setup failed"
ip link set lo up
cd /payload
sh /payload/test.sh
echo "SC_HIL_RESULT rc=$?"
echo o > /proc/sysrq-trigger
sleep 5
INIT
    chmod +x "$tree/init"
    (cd "$tree" && find . | busybox cpio -o -H newc 2>/dev/null | gzip -1) > "$tree.cpio.gz"
    log=${SC_HIL_LOG:-$(dirname "$payload")/vm-console.log}
    local monitor=(-monitor none)
    [ -n "${SC_HIL_MONITOR:-}" ] && monitor=(-monitor "unix:$SC_HIL_MONITOR,server,nowait")
    local display_args=(-display none -vga none)
    [ -f "$payload/want-display" ] && display_args=(-display none -vga std)
    # shellcheck disable=SC2086
    timeout "$timeout_s" qemu-system-x86_64 -accel tcg -m 512 -nographic -no-reboot \
        "${display_args[@]}" -serial stdio "${monitor[@]}" \
        -kernel "$cache/vmlinuz" -initrd "$tree.cpio.gz" \
        -append "console=ttyS0 quiet panic=-1 oops=panic vt.global_cursor_default=0" ${SC_HIL_QEMU_ARGS:-} \
        < /dev/null > "$log" 2>&1 || true
    rm -f "$tree.cpio.gz"
    local rc
    rc=$(sed -n 's/.*SC_HIL_RESULT rc=\([0-9]*\).*/\1/p' "$log" | tail -n 1)
    if [ -z "$rc" ]; then
        echo "hil: no result line from the VM (timeout ${timeout_s}s?); console log: $log" >&2
        tail -n 30 "$log" >&2
        return 3
    fi
    return "$rc"
}

case "${1:-}" in
prepare) prepare ;;
run) [ $# -ge 2 ] || die "usage: $0 run PAYLOAD_DIR"; run "$2" ;;
*) echo "usage: $0 prepare | run PAYLOAD_DIR" >&2; exit 2 ;;
esac
