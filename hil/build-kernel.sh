#!/bin/sh
# Step 2 of make hil: from the cached Debian debs, for each kernel flavour (amd64, rt-amd64):
# the uncompressed vmlinux (boots in ~2 s under TCG instead of decompressing the bzImage),
# modules.dep (depmod -b), the list of modules the VM loads (modprobe --show-depends), and
# gpio-sim.ko built out of tree against the extracted headers from three files of Debian's
# linux-source, edited at build time (no kernel source is kept in the tree).
# Usage: hil/build-kernel.sh CACHE_DIR ABI OUT_DIR     (ABI e.g. 6.1.0-56)
# Writes OUT_DIR/<KV>/{vmlinux,modules.order,gpio-sim.ko} with KV = ABI-amd64, ABI-rt-amd64.
# Idempotent: each product is rebuilt only when missing.
set -eu
cache=$1 abi=$2
mkdir -p "$3"; out=$(cd "$3" && pwd)   # absolute: make -C and the Makefile include need it
say() { echo "hil: $*" >&2; }
deb() { # the cached .deb of package $1
    set -- "$cache/${1}_"*.deb
    [ -f "$1" ] || { say "missing $1 (run hil/fetch-debs.sh)"; exit 1; }
    ls -t "$@" | head -n 1
}
mkdir -p "$out"
kroot="$out/kroot"   # image + headers debs unpacked here (dpkg-deb -x), never into /
major=${abi%%-*}; major=${major%.*}

# Modules the VM needs (their dependencies are added by modprobe --show-depends).
# kvaser_pci: the SJA1000 CAN controllers qemu emulates (two on one emulated bus: can0, can1),
# real CAN hardware drivers with bit timing, error counters and bus-off.
MODULES="can-raw vcan configfs dummy_hcd libcomposite usb_f_fs kvaser_pci"

unpack() { # package -> kroot, once
    stamp="$kroot/.unpacked-$1"
    [ -f "$stamp" ] && return 0
    say "unpack   $1"
    dpkg-deb -x "$(deb "$1")" "$kroot"
    touch "$stamp"
}
# An image package: only the kernel, the module lists and the module directories the VM's
# modules and their dependencies live in (a tenth of the package's 400 MB).
unpack_image() { # package kv
    stamp="$kroot/.unpacked-$1"
    [ -f "$stamp" ] && return 0
    say "unpack   $1 (vmlinuz, can, configfs, usb modules)"
    m="./lib/modules/$2"
    mkdir -p "$kroot"
    dpkg-deb --fsys-tarfile "$(deb "$1")" | tar -x -C "$kroot" --wildcards \
        "./boot/vmlinuz-$2" "$m/modules.builtin" "$m/modules.builtin.modinfo" "$m/modules.order" \
        "$m/kernel/net/can" "$m/kernel/drivers/net/can" "$m/kernel/fs/configfs" "$m/kernel/drivers/usb"
    touch "$stamp"
}

# The three gpio-sim sources, extracted once per source version into the cache.
src_ver=$(basename "$(deb "linux-source-$major")" .deb)
srcdir="$out/src-$src_ver"
if [ ! -f "$srcdir/.done" ]; then
    say "extract  gpio-sim.c, gpiolib.h, irq_sim.c from $src_ver (~15 s)"
    rm -rf "$srcdir" && mkdir -p "$srcdir"
    dpkg-deb --fsys-tarfile "$(deb "linux-source-$major")" |
        tar -xO "./usr/src/linux-source-$major.tar.xz" |
        tar -xJ -C "$srcdir" --strip-components=1 \
            "linux-source-$major/drivers/gpio/gpio-sim.c" \
            "linux-source-$major/drivers/gpio/gpiolib.h" \
            "linux-source-$major/kernel/irq/irq_sim.c"
    touch "$srcdir/.done"
fi

for flav in amd64 rt-amd64; do
    kv="$abi-$flav"
    common="linux-headers-$abi-common"
    [ "$flav" = rt-amd64 ] && common="linux-headers-$abi-common-rt"
    unpack_image "linux-image-$kv" "$kv"
    unpack "linux-headers-$kv"
    unpack "$common"
    unpack "linux-kbuild-$major"
    d="$out/$kv"
    mkdir -p "$d"

    # vmlinux: the bzImage's payload is one xz stream; find its magic FD 37 7A 58 5A 00.
    if [ ! -s "$d/vmlinux" ]; then
        z="$kroot/boot/vmlinuz-$kv"
        off=$(LC_ALL=C grep -obUaP '\xfd7zXZ\x00' "$z" | head -n 1 | cut -d: -f1)
        [ -n "$off" ] || { say "no xz stream in $z"; exit 1; }
        tail -c +"$((off + 1))" "$z" | xz -dcq --single-stream >"$d/vmlinux.tmp" || true
        head -c 4 "$d/vmlinux.tmp" | grep -q 'ELF' || { say "$z: xz payload is not an ELF vmlinux"; exit 1; }
        mv "$d/vmlinux.tmp" "$d/vmlinux"
        say "vmlinux  $kv ($(du -m "$d/vmlinux" | cut -f1) MB, from offset $off)"
    fi

    # modules.dep for this tree, then the ordered load list for the VM's init.
    # (made again when the module list changes)
    if [ ! -s "$d/modules.order" ] || [ "$(cat "$d/modules.want" 2>/dev/null)" != "$MODULES" ]; then
        depmod -b "$kroot" "$kv"
        for m in $MODULES; do modprobe -d "$kroot" -S "$kv" --show-depends "$m"; done >"$d/show-depends"
        # "insmod /abs/path.ko [opts]" in load order; "builtin x" needs nothing.
        awk '$1 == "insmod" && !seen[$2]++ { print $2 }' "$d/show-depends" |
            sed "s|^$kroot/||" >"$d/modules.order"
        echo "$MODULES" >"$d/modules.want"
        say "modules  $kv: $(wc -l <"$d/modules.order") to load ($(grep -c builtin "$d/show-depends" || true) built in)"
    fi

    # gpio-sim, out of tree. The headers' Makefile includes the -common tree by absolute path:
    # point it at our unpacked copy instead.
    if [ ! -s "$d/gpio-sim.ko" ]; then
        hdr="$kroot/usr/src/linux-headers-$kv"
        commondir=$(basename "$kroot/usr/src/$common")
        sed -i "s|^include /usr/src/$commondir/Makefile|include $kroot/usr/src/$commondir/Makefile|" "$hdr/Makefile"
        b="$d/gpio-sim-build"
        rm -rf "$b" && mkdir -p "$b"
        cp "$srcdir/drivers/gpio/gpio-sim.c" "$b/gpio_sim_main.c"
        cp "$srcdir/drivers/gpio/gpiolib.h" "$b/gpiolib.h"
        # irq_sim.c linked into the module: its exports would clash with nothing but are not
        # needed, and irq_to_desc() is not exported to modules, so hand the irq over by number.
        sed -e '/^EXPORT_SYMBOL_GPL(/d' \
            -e 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq(irqnum);/' \
            "$srcdir/kernel/irq/irq_sim.c" >"$b/irq_sim.c"
        grep -q 'generic_handle_irq(irqnum);' "$b/irq_sim.c" || { say "irq_sim.c edit did not apply"; exit 1; }
        printf 'obj-m := gpio-sim.o\ngpio-sim-y := gpio_sim_main.o irq_sim.o\n' >"$b/Kbuild"
        say "build    gpio-sim.ko for $kv"
        make -s -C "$hdr" M="$(cd "$b" && pwd)" modules >"$b/build.log" 2>&1 || {
            tail -n 20 "$b/build.log" >&2; say "gpio-sim build failed for $kv (log $b/build.log)"; exit 1; }
        strip --strip-debug -o "$d/gpio-sim.ko" "$b/gpio-sim.ko"
    fi
done
say "kernels ready in $out"
