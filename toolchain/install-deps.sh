#!/bin/sh
# Installs the Debian 12 packages argil needs to build and test, and only the
# missing ones. Idempotent: a second run installs nothing and says so.
# Usage: toolchain/install-deps.sh [--check] [compile|build|test|fuzz|cross|render|bench|hil ...]
#   compile: what compiling `make all` needs (headers and libraries only); build: what `make` and `make run` need (includes render); test: + the test tools;
#   fuzz: + clang/libFuzzer; render: argil view/plot (GLFW, EGL, Mesa, stb, Xvfb);
#   bench: + valgrind and the third-party meshers make bench compares against.
#   hil: qemu and the tools put into the HIL VM (the kernel debs are fetched, not installed).
#   With no group: all of them. --check lists what is missing and exits 1 if anything is.
set -eu

BUILD_PKGS="make gcc libc6-dev libgpiod-dev libusb-1.0-0-dev libsodium-dev libinih-dev" # the build (libgpiod 1.6: argil-board's GPIO lines;
# libusb: its header for the host's USB link, the library itself is opened with dlopen at run time;
# libsodium: the UDP link's keyed BLAKE2b tags and the link key, docs/link.md "Link key";
# libinih: the reader of argil-board's INI file, docs/board.md "The configuration file")
TEST_PKGS="libcmocka-dev assimp-utils valgrind" # unit-test runner; a third-party mesh reader; callgrind (+ valgrind/callgrind.h) for make bench
FUZZ_PKGS="clang libclang-rt-14-dev"     # libFuzzer targets (make fuzz)
# argil view / argil plot (docs/render.md): headers at build time (GL, EGL, GLFW, stb's PNG
# writer); at run time libglfw/libEGL/Mesa are opened with dlopen, so no link flags are needed.
# Mesa's llvmpipe renders with no GPU (EGL surfaceless); Xvfb gives GLFW a display in tests.
# the headers of the render packages below, all that compiling needs of them
RENDER_HDR_PKGS="libglfw3-dev libepoxy-dev libegl-dev libgl-dev libstb-dev"
RENDER_PKGS="libglfw3-dev libepoxy-dev libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri libstb-dev xvfb xauth"
# make cross (and the cross tier of make test): aarch64 board daemon + its tests under
# qemu-user, the Cortex-M image under qemu-system-arm. The :arm64 libraries need Debian's
# arm64 architecture enabled (done below, once).
# make bench: callgrind, and scikit-image's and OpenVDB's marching cubes for comparison.
BENCH_PKGS="valgrind python3-skimage python3-openvdb"
# make hil (hil/README.md): qemu boots Debian's kernel; busybox-static, can-utils and gpiod go
# into its initramfs; cpio packs it, kmod's depmod/modprobe resolve the module closure;
# iproute2's ip sets the emulated CAN controllers' bit rate (busybox's ip has no "type can").
HIL_PKGS="qemu-system-x86 busybox-static cpio kmod can-utils gpiod xz-utils iproute2"
CROSS_PKGS="gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user qemu-system-arm gcc-arm-none-eabi libnewlib-arm-none-eabi libgpiod-dev:arm64 libcmocka-dev:arm64 libsodium-dev:arm64 libinih-dev:arm64"

check_only=0
groups=""
for a in "$@"; do
    case "$a" in
        --check) check_only=1 ;;
        compile|build|test|fuzz|cross|render|bench|hil) groups="$groups $a" ;;
        *) echo "toolchain: unknown argument '$a' (use --check, compile, build, test, fuzz, cross, render, bench, hil)" >&2; exit 2 ;;
    esac
done
[ -n "$groups" ] || groups="build test fuzz cross render"
PACKAGES=""
for g in $groups; do
    case "$g" in
        compile) PACKAGES="$PACKAGES $BUILD_PKGS $RENDER_HDR_PKGS" ;;
        build|render) PACKAGES="$PACKAGES $BUILD_PKGS $RENDER_PKGS" ;;
        test) PACKAGES="$PACKAGES $BUILD_PKGS $RENDER_PKGS $TEST_PKGS" ;;
        fuzz) PACKAGES="$PACKAGES $BUILD_PKGS $RENDER_PKGS $FUZZ_PKGS" ;;
        cross) PACKAGES="$PACKAGES $BUILD_PKGS $RENDER_PKGS $CROSS_PKGS" ;;
        bench) PACKAGES="$PACKAGES $BUILD_PKGS $RENDER_PKGS $BENCH_PKGS" ;;
        hil) PACKAGES="$PACKAGES $BUILD_PKGS $RENDER_PKGS $HIL_PKGS" ;;
    esac
done

missing=""
for p in $(echo $PACKAGES | tr ' ' '\n' | sort -u); do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
        missing="$missing $p"
    fi
done

if [ -z "$missing" ]; then
    echo "toolchain: all packages present for:$groups"
    exit 0
fi
if [ "$check_only" = 1 ]; then
    echo "toolchain: missing:$missing"
    exit 1
fi

echo "toolchain: installing:$missing"
if [ "$(id -u)" != 0 ]; then
    if command -v sudo >/dev/null 2>&1; then SUDO=sudo; else
        echo "toolchain: not root and no sudo; install as root:$missing" >&2
        exit 1
    fi
else
    SUDO=""
fi
export DEBIAN_FRONTEND=noninteractive
need_update=0
case "$missing" in
    *:arm64*)
        if ! dpkg --print-foreign-architectures | grep -qx arm64; then
            echo "toolchain: enabling Debian's arm64 architecture for the cross libraries"
            $SUDO dpkg --add-architecture arm64
            need_update=1
        fi ;;
esac
[ "$need_update" = 1 ] && $SUDO apt-get update -q
# A fresh machine has empty package lists; refresh them once if an install fails.
if ! $SUDO apt-get install -y -q --no-install-recommends $missing; then
    echo "toolchain: refreshing package lists (apt-get update)"
    $SUDO apt-get update -q
    $SUDO apt-get install -y -q --no-install-recommends $missing
fi
echo "toolchain: installed:$missing"
