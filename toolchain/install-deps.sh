#!/bin/sh
# Installs the Debian 12 packages argil needs to build and test, and only the
# missing ones. Idempotent: a second run installs nothing and says so.
# Usage: toolchain/install-deps.sh [--check]   (--check: list what is missing, exit 1 if any)
set -eu

# One line per package: what it is for is in the comment beside it.
PACKAGES="
make
gcc
libc6-dev
libcmocka-dev
clang
libclang-rt-14-dev
assimp-utils
"
# make, gcc, libc6-dev  : the build
# libcmocka-dev         : unit-test runner
# clang, libclang-rt-14-dev : libFuzzer targets (make fuzz)
# assimp-utils          : tests load exported meshes with a third-party reader

missing=""
for p in $PACKAGES; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
        missing="$missing $p"
    fi
done

if [ -z "$missing" ]; then
    echo "toolchain: all build dependencies present"
    exit 0
fi
if [ "${1:-}" = "--check" ]; then
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
# A fresh machine has empty package lists; refresh them once if an install fails.
if ! $SUDO apt-get install -y -q --no-install-recommends $missing; then
    echo "toolchain: refreshing package lists (apt-get update)"
    $SUDO apt-get update -q
    $SUDO apt-get install -y -q --no-install-recommends $missing
fi
echo "toolchain: installed:$missing"
