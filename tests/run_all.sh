#!/bin/sh
# Runs the test tiers named (default: all) and ends with one summary line:
#   N passed, N failed, N skipped
# Usage: tests/run_all.sh SAN_BUILD_DIR REL_BUILD_DIR [unit] [sil] [sys] [cross] [hil]
#   unit   the cmocka binaries SAN/tests/test_* (ASan + UBSan) and tests/runner/test_*.sh
#   sil    the SIL scenarios SAN/sil/test_*
#   sys    tests/sys/test_*.sh but test_cross.sh and test_hil.sh
#   cross  tests/sys/test_cross.sh (aarch64 under qemu-user, Cortex-M on qemu-system-arm)
#   hil    tests/sys/test_hil.sh (the VM rig; its output is shown as it runs)
# Every cmocka test and every check a script reports (tests/lib/report.sh) is one counted test;
# how crashes, time-outs and exit status 77 (skip) count: tests/lib/run.sh. Each test runs under
# a time limit: the tier's (unit 300 s, sil 600 s, sys 300 s, cross 900 s, hil 1500 s), else
# tests/timeouts (NAME SECONDS lines), else $TEST_TIMEOUT_<NAME> or $TEST_TIMEOUT in seconds.
set -u
# Tests that want a display make their own (xvfb-run); without this, every other `argil sculpt`
# would open a window on the caller's display and run at real-time pace.
unset DISPLAY WAYLAND_DISPLAY
SAN=$1
REL=$2
shift 2
export SAN REL
tiers=${*:-unit sil sys cross hil}
. tests/lib/run.sh
run_init "$SAN/test-logs"

# limit NAME TIER_DEFAULT: tests/timeouts first, then the environment (run_timeout).
limit() {
    lim=$(awk -v n="$1" '$1 == n && $2 ~ /^[0-9]+$/ { print $2 }' tests/timeouts 2>/dev/null | tail -n 1)
    run_timeout "$1" "${lim:-$2}"
}

for tier in $tiers; do
    case "$tier" in
    unit)
        echo "== unit tests (ASan + UBSan)"
        for t in "$SAN"/tests/test_*; do
            [ -x "$t" ] && run_test cmocka "$t" "$(limit "$(basename "$t")" 300)"
        done
        for t in tests/runner/test_*.sh; do
            [ -f "$t" ] && run_test script "$t" "$(limit "$(basename "$t" .sh)" 300)"
        done
        ;;
    sil)
        echo "== SIL scenarios (lockstep, virtual clock)"
        for t in "$SAN"/sil/test_*; do
            [ -x "$t" ] && run_test cmocka "$t" "$(limit "$(basename "$t")" 600)"
        done
        ;;
    sys)
        echo "== system tests (the argil program and its files)"
        for t in tests/sys/test_*.sh; do
            case "$t" in */test_cross.sh|*/test_hil.sh) continue ;; esac
            [ -f "$t" ] && run_test script "$t" "$(limit "$(basename "$t" .sh)" 300)"
        done
        ;;
    cross)
        echo "== cross (aarch64 under qemu-user, Cortex-M on qemu-system-arm)"
        run_test script tests/sys/test_cross.sh "$(limit test_cross 900)"
        ;;
    hil)
        echo "== HIL rig (qemu VM, real argil-board)"
        run_test script tests/sys/test_hil.sh "$(limit test_hil 1500)" live
        ;;
    *)
        echo "run_all.sh: unknown tier '$tier' (unit, sil, sys, cross, hil)" >&2
        exit 2
        ;;
    esac
done

run_summary
