#!/bin/sh
# The HIL tier (make hil, make test): boots the VM rig (hil/hil.sh; Debian's amd64 and PREEMPT_RT
# kernels under qemu TCG) with the real argil-board from $REL on real vcan, gpio-sim and a
# FunctionFS gadget on dummy_hcd, runs hil/plan.txt and reports each check of each rig to the
# runner (tests/lib/report.sh) as rig/name: PLAN from hil.sh's "rig 'R' plans N checks" lines,
# PASS/FAIL/SKIP from its "  [R] PASS name: detail" lines; a planned check that never reports
# counts as failed. Passes when every check passed and hil.sh agrees.
# The packages come from `make hil`/`make test` (toolchain/install-deps.sh hil); the kernel debs
# are fetched into the cache on first use (hil/README.md). HIL_SH replaces `sh hil/hil.sh`
# (tests/runner/test_runner.sh plays recorded runs through it).
set -eu
. tests/lib/report.sh
build=$(dirname "$REL")
for b in argil-board board_udp_client hil-probe hil-host; do
    [ -x "$REL/$b" ] || { echo "FAIL: $REL/$b not built"; exit 1; }
done
out=$(mktemp)
trap 'rm -f "$out"' EXIT
st=0
# hil.sh's own lines go to the log as they come; its status is kept past the pipe.
{ ${HIL_SH:-sh hil/hil.sh} "$build" 2>&1 || echo "HIL-SH-STATUS $?"; } | tee "$out"
st=$(sed -n 's/^HIL-SH-STATUS //p' "$out")
sed -n "s/^hil: rig '[a-z0-9]*' plans \([0-9]*\) checks$/\1/p" "$out" | while read -r n; do report_plan "$n"; done
[ -z "${RESULTS_FILE:-}" ] || hil_results <"$out" >>"$RESULTS_FILE"
checks=$(hil_results <"$out" | wc -l)
[ -z "$st" ] || { echo "FAIL: make hil's rig reported failures (status $st) after $checks checks; logs in $build/hil/run-*/"; exit 1; }
echo "hil: $checks checks, every one passed or skipped in the VM (logs in $build/hil/run-*/)"
