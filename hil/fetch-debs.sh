#!/bin/sh
# Step 1 of make hil: fetches Debian's kernel packages for the VM into a cache directory with
# `apt-get download` (never installed into this system) and prints the kernel version to use.
# Idempotent: a package already in the cache is not downloaded again.
# Usage: hil/fetch-debs.sh CACHE_DIR   (stdout: the last line is the ABI, e.g. 6.1.0-56)
set -eu
cache=${1:?usage: hil/fetch-debs.sh CACHE_DIR}
mkdir -p "$cache"
say() { echo "hil: $*" >&2; }

# linux-image-amd64 depends on exactly one linux-image-<abi>-amd64: that is the current kernel.
resolve_abi() {
    apt-cache depends linux-image-amd64 2>/dev/null |
        sed -n 's/^ *Depends: linux-image-\([0-9.]*-[0-9]*\)-amd64$/\1/p' | head -n 1
}
abi=$(resolve_abi)
if [ -z "$abi" ]; then
    say "apt-cache knows no linux-image-amd64; refreshing package lists (apt-get update)"
    if [ "$(id -u)" = 0 ]; then apt-get update -q >&2; else sudo apt-get update -q >&2; fi
    abi=$(resolve_abi)
fi
[ -n "$abi" ] || { say "cannot resolve the kernel ABI from 'apt-cache depends linux-image-amd64'"; exit 1; }
major=${abi%%-*}; major=${major%.*}   # 6.1.0-56 -> 6.1

pkgs="linux-image-$abi-amd64 linux-image-$abi-rt-amd64
      linux-headers-$abi-amd64 linux-headers-$abi-rt-amd64
      linux-headers-$abi-common linux-headers-$abi-common-rt
      linux-kbuild-$major linux-source-$major"
# One apt-cache call for all (each call costs seconds): "package version" per line.
versions=$(apt-cache policy $pkgs | awk '/^[^ ]/ { sub(":$", "", $1); p = $1 } /^ *Candidate:/ { print p, $2 }')
fetched=0
for p in $pkgs; do
    ver=$(echo "$versions" | awk -v p="$p" '$1 == p { print $2 }')
    if [ -z "$ver" ] || [ "$ver" = "(none)" ]; then say "no candidate version for $p"; exit 1; fi
    file_ver=$(echo "$ver" | sed 's/:/%3a/')
    if ls "$cache/${p}_${file_ver}_"*.deb >/dev/null 2>&1; then
        say "cached   $p $ver"
        continue
    fi
    say "download $p $ver"
    # As root apt warns that its sandbox user cannot write the cache and downloads unsandboxed.
    (cd "$cache" && apt-get download -q "$p=$ver" 2>&1 | grep -v 'unsandboxed as root' >&2) || true
    ls "$cache/${p}_${file_ver}_"*.deb >/dev/null 2>&1 || { say "apt-get download $p=$ver failed"; exit 1; }
    fetched=$((fetched + 1))
done
say "kernel packages for $abi: $fetched downloaded, cache $cache ($(du -sh "$cache" | cut -f1))"
echo "$abi"
