#!/bin/sh
# Step 3 of make hil: the VM's initramfs for one kernel: busybox-static, the kernel's modules
# (modules.order from hil/build-kernel.sh) and gpio-sim.ko, can-utils, the gpiod tools, the argil
# binaries found in REL (argil-board, board_udp_client, hil-probe, hil-host; argil-sim and argil when
# built) with their shared libraries, firmware/board/argil-gadget.sh, and hil/ (init, plan, rig
# config, checks, scenarios).
# Usage: hil/mkinitramfs.sh KERNEL_DIR KROOT REL OUT.cpio.gz
set -eu
kd=$1 kroot=$2 rel=$3 out=$4
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/.." && pwd)
say() { echo "hil: $*" >&2; }
r=$(mktemp -d)
trap 'rm -rf "$r"' EXIT
mkdir -p "$r/bin" "$r/usr/bin" "$r/hil" "$r/hil-out" "$r/proc" "$r/sys" "$r/dev" "$r/tmp" "$r/etc" "$r/root"

cp /bin/busybox "$r/bin/busybox"
file -L /bin/busybox 2>/dev/null | grep -q 'statically linked' || [ ! -x /usr/bin/file ] ||
    { say "/bin/busybox is not static (install busybox-static)"; exit 1; }

# Modules in load order, at their /lib/modules paths.
while read -r ko; do
    mkdir -p "$r/$(dirname "$ko")"
    cp "$kroot/$ko" "$r/$ko"
done <"$kd/modules.order"
cp "$kd/modules.order" "$kd/gpio-sim.ko" "$r/hil/"

# Programs and the libraries ldd names for them (the loader included).
bins="/usr/bin/candump /usr/bin/cansend /usr/bin/cangen /usr/bin/gpiodetect /usr/bin/gpioinfo
      /usr/bin/gpioget /usr/bin/gpioset /usr/bin/gpiomon"
for b in argil-board board_udp_client hil-probe hil-host; do
    [ -x "$rel/$b" ] || { say "missing $rel/$b (build it first)"; exit 1; }
    bins="$bins $rel/$b"
done
extra=""
for b in argil-sim argil-hil-check argil; do
    if [ -x "$rel/$b" ]; then bins="$bins $rel/$b"; extra="$extra $b"; fi
done
for b in $bins; do
    [ -x "$b" ] || { say "missing $b"; exit 1; }
    cp "$b" "$r/usr/bin/"
    ldd "$b" | awk '/=> \// { print $3 } /^\t\/[^ ]+ \(/ { print $1 }' | while read -r lib; do
        [ -e "$r$lib" ] && continue
        mkdir -p "$r$(dirname "$lib")"
        cp -L "$lib" "$r$lib"
    done
done
# iproute2's ip as ip-full (busybox's ip stays "ip"): it sets a real CAN controller's bit rate.
if [ -x /bin/ip ]; then
    cp /bin/ip "$r/usr/bin/ip-full"
    ldd /bin/ip | awk '/=> \// { print $3 } /^\t\/[^ ]+ \(/ { print $1 }' | while read -r lib; do
        [ -e "$r$lib" ] && continue
        mkdir -p "$r$(dirname "$lib")"
        cp -L "$lib" "$r$lib"
    done
else
    say "iproute2 not installed: the VM's CAN controllers (can0, can1) stay down"
fi
# argil opens libusb with dlopen (no ldd entry): bring it and what it needs.
if [ -f "$r/usr/bin/argil" ]; then
    usb=$(ldconfig -p | awk '/libusb-1.0.so.0 .*x86-64/ { print $NF; exit }')
    if [ -n "$usb" ]; then
        # Into /lib/x86_64-linux-gnu, where the loader looks without an ld.so.cache.
        d=/lib/x86_64-linux-gnu
        mkdir -p "$r$d"
        for lib in "$usb" $(ldd "$usb" | awk '/=> \// { print $3 }'); do
            b=$(basename "$lib")
            [ -e "$r$d/$b" ] || cp -L "$lib" "$r$d/$b"
        done
    else
        say "libusb-1.0.so.0 not installed: the VM's USB host checks will fail"
    fi
fi
for b in argil-board board_udp_client hil-probe hil-host argil-sim argil-hil-check argil; do
    [ -f "$r/usr/bin/$b" ] && strip --strip-debug "$r/usr/bin/$b"
done

cp "$here/vm/init" "$r/init"
cp "$here/vm/mountpoint" "$r/bin/mountpoint"
cp "$top/firmware/board/argil-gadget.sh" "$r/usr/bin/argil-gadget.sh"
cp "$here/run-plan.sh" "$here/lib.sh" "$r/hil/"
cp "${HIL_PLAN:-$here/plan.txt}" "$r/hil/plan.txt"   # HIL_PLAN: another plan file
cp "$here/rig-vm.conf" "$r/hil/rig.conf"
[ -d "$here/scenarios" ] && cp -r "$here/scenarios" "$r/hil/"
chmod 755 "$r/init" "$r/bin/mountpoint" "$r/usr/bin/argil-gadget.sh" "$r/hil/run-plan.sh"
echo "root:x:0:0:root:/root:/bin/sh" >"$r/etc/passwd"

(cd "$r" && find . | LC_ALL=C sort | cpio -o -H newc --quiet) | gzip -1 >"$out.tmp"
mv "$out.tmp" "$out"
say "initramfs $(basename "$out"): $(du -k "$out" | cut -f1) KiB (optional binaries:${extra:- none})"
