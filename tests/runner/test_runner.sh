#!/bin/sh
# The runner's own test (make unit): tests/lib/run.sh on fake cmocka binaries and scripts in
# tests/runner/fixtures/ that crash, hang, skip, fail after passing and report checks, and
# tests/sys/test_hil.sh on recorded make hil runs; each case is one check of the counts
# "passed failed skipped" it gives, and of what it prints.
set -u
. tests/lib/report.sh
fx=tests/runner/fixtures
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# one CASE KIND PATH SECONDS [VAR=VALUE...]: runs PATH through the runner library in a fresh shell
# with its own logs; "P F S" on stdout, the runner's lines in $tmp/CASE/out.
one() {
    one_case=$1 one_kind=$2 one_path=$3 one_secs=$4
    shift 4
    mkdir -p "$tmp/$one_case"
    env -u RESULTS_FILE -u TEST_LIVE "$@" sh -c '. tests/lib/run.sh; run_init "$1/logs"
        run_test "$2" "$3" "$4" >"$1/out" 2>&1; echo "$run_passed $run_failed $run_skipped"' \
        sh "$tmp/$one_case" "$one_kind" "$one_path" "$one_secs"
}

# expect CASE "P F S" KIND PATH SECONDS [VAR=VALUE...]
expect() {
    ex_case=$1 ex_want=$2
    shift 2
    ex_got=$(one "$ex_case" "$@")
    if [ "$ex_got" = "$ex_want" ]; then
        report PASS "$ex_case" "$ex_got (passed failed skipped)"
    else
        report FAIL "$ex_case" "counted $ex_got, want $ex_want; the runner printed: $(tr '\n' '|' <"$tmp/$ex_case/out" | cut -c1-400)"
    fi
}

# printed CASE WHAT PATTERN: the runner's lines for CASE match the extended regular expression.
printed() {
    if grep -Eq "$3" "$tmp/$1/out"; then
        report PASS "$1-$2" "/$3/"
    else
        report FAIL "$1-$2" "no line matches /$3/ in: $(tr '\n' '|' <"$tmp/$1/out" | cut -c1-400)"
    fi
}

report_plan 27

# cmocka binaries: every test counted; crashed or hung, the tests it never reached are failed.
expect cmocka-mixed "3 1 1" cmocka "$fx/cmocka_mixed" 20
printed cmocka-mixed counts '^FAIL cmocka_mixed \(3 passed, 1 failed, 1 skipped\)'
printed cmocka-mixed skip-listed '^    SKIP c'
expect cmocka-crash "2 3 0" cmocka "$fx/cmocka_crash" 20
printed cmocka-crash unrun '3 planned test\(s\) never reported \(killed by signal 11\)'
t0=$(date +%s)
expect cmocka-hang "1 2 0" cmocka "$fx/cmocka_hang" 2
printed cmocka-hang timed-out '^FAIL cmocka_hang \(1 passed, 2 failed\) — timed out after 2 s'
printed cmocka-hang log-tail '^    \[ RUN      \] test_waits_forever'
expect cmocka-leak "2 1 0" cmocka "$fx/cmocka_leak" 20
expect cmocka-silent "0 1 0" cmocka "$fx/cmocka_silent" 20

# Scripts: the checks they report, PLAN'd ones missing failed; otherwise one test by exit status.
expect script-checks "1 2 1" script "$fx/script_checks.sh" 20
printed script-checks fail-listed '^    FAIL second: force 3.2 N > 2 N'
expect script-passes-then-dies "2 1 0" script "$fx/script_passes_then_dies.sh" 20
expect script-ok "1 0 0" script "$fx/script_ok.sh" 20
expect script-fail "0 1 0" script "$fx/script_fail.sh" 20
expect script-skip "0 0 1" script "$fx/script_skip.sh" 20
printed script-skip why '^SKIP script_skip: skip: no qemu-aarch64 on this machine'
expect script-hang "0 1 0" script "$fx/script_hang.sh" 2
expect script-bad-line "1 1 0" script "$fx/script_bad_line.sh" 20
# Two time-outs of 2 s (and the 10 s kill grace unused): the runner did not wait for the children.
t1=$(date +%s)
if [ $((t1 - t0)) -lt 20 ]; then
    report PASS hang-children-killed "$((t1 - t0)) s for the cases from cmocka-hang on"
else
    report FAIL hang-children-killed "$((t1 - t0)) s for the cases from cmocka-hang on: a time-out waited for its children"
fi

# Time limits: the per-test variable wins over TEST_TIMEOUT, which wins over the default.
lim=$(env TEST_TIMEOUT=50 TEST_TIMEOUT_test_a_b=7 sh -c \
    '. tests/lib/run.sh; run_timeout test-a.b 300; run_timeout other 300' | tr '\n' ' ')
if [ "$lim" = "7 50 " ]; then report PASS timeout-override "$lim"; else report FAIL timeout-override "got '$lim', want '7 50 '"; fi

# The HIL tier on recorded runs (make hil's output): each VM check counted as rig/name.
mkdir -p "$tmp/rel"
for b in argil-board board_udp_client hil-probe hil-host; do printf '#!/bin/sh\n' >"$tmp/rel/$b"; chmod +x "$tmp/rel/$b"; done
hil() { expect "$1" "$2" script tests/sys/test_hil.sh 20 REL="$tmp/rel" HIL_SH="sh $fx/fake_hil.sh $3 $4"; }
hil hil-pass "35 0 0" "$fx/hil_pass.out" 0
hil hil-fail "6 1 0" "$fx/hil_fail.out" 1
printed hil-fail fail-listed '^    FAIL rt/rt-scenario-estop: 5 passed, 1 failed'
hil hil-died "9 25 1" "$fx/hil_died.out" 1
printed hil-died unrun '25 planned test\(s\) never reported'
printf "hil: rig 'std' plans 28 checks\nhil: rig 'rt' plans 7 checks\nE: apt-get download failed\n" >"$tmp/hil_nodebs.out"
hil hil-no-debs "0 35 0" "$tmp/hil_nodebs.out" 1
