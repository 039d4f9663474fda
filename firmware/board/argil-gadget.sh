#!/bin/sh
# Board side: creates the USB gadget (configfs) with one FunctionFS function and mounts it at
# /dev/ffs-argil, so `argil-board --link ffs:/dev/ffs-argil` can write its descriptors. After
# argil-board has started (it writes the descriptors and opens the endpoints), bind the UDC:
#   argil-gadget.sh bind
set -eu
G=/sys/kernel/config/usb_gadget/argil
case "${1:-setup}" in
setup)
    modprobe libcomposite 2>/dev/null || true
    mountpoint -q /sys/kernel/config || mount -t configfs none /sys/kernel/config
    mkdir -p "$G" && cd "$G"
    echo 0x1209 > idVendor
    echo 0x0001 > idProduct
    mkdir -p strings/0x409 configs/c.1/strings/0x409 functions/ffs.argil
    echo "argil" > strings/0x409/manufacturer
    echo "argil haptic board" > strings/0x409/product
    echo "argil board link" > configs/c.1/strings/0x409/configuration
    [ -e configs/c.1/ffs.argil ] || ln -s functions/ffs.argil configs/c.1/
    mkdir -p /dev/ffs-argil
    mountpoint -q /dev/ffs-argil || mount -t functionfs argil /dev/ffs-argil
    ;;
bind)
    ls /sys/class/udc | head -n 1 > "$G/UDC"
    ;;
*)
    echo "usage: argil-gadget.sh [setup|bind]" >&2
    exit 2
    ;;
esac
