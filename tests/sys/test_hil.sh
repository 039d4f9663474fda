#!/bin/sh
# The HIL tier in make test: boots the VM rig (hil/hil.sh; Debian's amd64 and PREEMPT_RT
# kernels under qemu TCG) with the real argil-board from $REL on real vcan, gpio-sim and a
# FunctionFS gadget on dummy_hcd, runs hil/plan.txt and passes when every check passed.
# The packages come from `make test` (toolchain/install-deps.sh hil); the kernel debs are
# fetched into the cache on first use (hil/README.md).
set -eu
build=$(dirname "$REL")
for b in argil-board board_udp_client hil-probe hil-host; do
    [ -x "$REL/$b" ] || { echo "FAIL: $REL/$b not built"; exit 1; }
done
st=0
sh hil/hil.sh "$build" || st=$?
# The summary line must be there and agree with the status.
[ "$st" = 0 ] || { echo "FAIL: make hil's rig reported failures (status $st); logs in $build/hil/run-*/"; exit 1; }
echo "hil: every check passed in the VM (logs in $build/hil/run-*/)"
