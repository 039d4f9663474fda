#!/bin/sh
# Runs every test tier that runs on this machine and ends with one summary line:
#   N passed, N failed
# Usage: tests/run_all.sh SAN_BUILD_DIR REL_BUILD_DIR
set -u
# Tests that want a display make their own (xvfb-run); without this, every other `argil sculpt`
# would open a window on the caller's display and run at real-time pace.
unset DISPLAY WAYLAND_DISPLAY
san=$1
rel=$2
passed=0
failed=0
failed_names=""
log_dir="$san/test-logs"
mkdir -p "$log_dir"

# A cmocka binary: count its own PASSED/FAILED lines (summary goes to stderr).
run_cmocka() {
    bin=$1
    name=$(basename "$bin")
    log="$log_dir/$name.log"
    "$bin" >"$log" 2>&1
    rc=$?
    p=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' "$log" | tail -n 1)
    f=$(sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' "$log" | tail -n 1)
    p=${p:-0}
    f=${f:-0}
    if [ "$rc" != 0 ] && [ "$f" = 0 ]; then
        f=1 # crashed or sanitizer abort before cmocka could count
    fi
    passed=$((passed + p))
    failed=$((failed + f))
    if [ "$f" != 0 ]; then
        failed_names="$failed_names $name"
        echo "FAIL $name ($p passed, $f failed) — log: $log"
        grep -E '^\[  (FAILED|ERROR) |ERROR|error|Sanitizer|runtime error' "$log" | head -n 20 | sed 's/^/    /'
    else
        echo "ok   $name ($p tests)"
    fi
}

# A shell-level test: one test, pass on exit 0.
run_sys() {
    script=$1
    name=$(basename "$script" .sh)
    log="$log_dir/$name.log"
    if SAN="$san" REL="$rel" sh "$script" >"$log" 2>&1; then
        passed=$((passed + 1))
        echo "ok   $name"
    else
        failed=$((failed + 1))
        failed_names="$failed_names $name"
        echo "FAIL $name — log: $log"
        tail -n 20 "$log" | sed 's/^/    /'
    fi
}

echo "== unit tests (ASan + UBSan)"
for t in "$san"/tests/test_*; do
    [ -x "$t" ] && run_cmocka "$t"
done
echo "== SIL scenarios (lockstep, virtual clock)"
for t in "$san"/sil/test_*; do
    [ -x "$t" ] && run_cmocka "$t"
done
echo "== system tests (the argil program and its files)"
for t in tests/sys/test_*.sh; do
    [ -f "$t" ] && run_sys "$t"
done

echo
[ -n "$failed_names" ] && echo "failed:$failed_names"
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
