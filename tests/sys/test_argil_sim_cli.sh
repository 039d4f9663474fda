#!/bin/sh
# argil-sim (the HIL rig's arm on a CAN bus) as a rig builder meets it: --help names every
# option; a bad option or value, a missing --can, an unreadable scenario each give one clear
# line and exit 2 before any bus is opened; a sub-step past the arm's stability bound is refused
# with that bound (docs/arm.md, "Integration").
set -eu
bin="$REL/argil-sim"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$bin" --help >"$tmp/help" || fail "--help exits non-zero"
for opt in can gpio-chip scenario log-dir seconds clock start-when start-timeout run-prio \
           arm-substep-us help; do
    grep -q -- "--$opt" "$tmp/help" || fail "--help does not explain --$opt"
done

. "$(dirname "$0")/expect_one_line_error.sh"
expect_error 2 "unknown or incomplete option '--frobnicate'" --frobnicate
expect_error 2 "--can IFACE is required" --scenario /dev/null
expect_error 2 "--run-prio '99': expected 1-98" --can vcan9 --run-prio 99
expect_error 2 "--clock 'tick': expected ticks or wall" --can vcan9 --clock tick
expect_error 2 "--arm-substep-us '0': expected 1-219" --can vcan9 --arm-substep-us 0
expect_error 2 "--arm-substep-us '220': expected 1-219 (longer makes the arm's friction overshoot" \
    --can vcan9 --arm-substep-us 220
expect_error 2 "--arm-substep-us '50us': expected 1-219" --can vcan9 --arm-substep-us 50us
expect_error 2 "nope.scn" --can vcan9 --scenario "$tmp/nope.scn"
echo "PASS: argil-sim refuses bad options with one line each"
