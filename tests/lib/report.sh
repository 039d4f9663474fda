# How a test reports several checks to the runner (tests/lib/run.sh), one line per check in
# the file named by $RESULTS_FILE (the runner sets it; unset, nothing is written):
#   PLAN n              n more checks are to come (optional; PLAN lines add up). A planned check
#                       that never reports - the script died, hung or stopped early - is failed.
#   PASS name [detail]  name: no spaces; detail: the rest of the line
#   FAIL name [detail]
#   SKIP name [detail]
# Each reported line is one counted test. The script's exit status counts too: non-zero with no
# FAIL line is one more failure; a script that reports nothing is one test (exit 0 passes, 77
# skips, anything else fails). Sourced by tests/lib/run.sh and by scripts that report checks.

# report PASS|FAIL|SKIP NAME [DETAIL...]: one check, to $RESULTS_FILE and to the log (stdout).
report() {
    report_st=$1 report_name=$2
    shift 2
    echo "$report_st $report_name${*:+: $*}"
    [ -z "${RESULTS_FILE:-}" ] || printf '%s %s %s\n' "$report_st" "$report_name" "$*" >>"$RESULTS_FILE"
}

# report_plan N: N more checks are to come.
report_plan() {
    [ -z "${RESULTS_FILE:-}" ] || echo "PLAN $1" >>"$RESULTS_FILE"
}

# cmocka_results PREFIX <LOG: a cmocka binary's output as result lines on stdout: PLAN N from
# each "[==========] Running N test(s)." and one PASS/FAIL/SKIP per test, named PREFIX + test
# name; the listing after "N test(s) run." is not counted twice.
cmocka_results() {
    awk -v pre="$1" '
        /^\[==========\] Running [0-9]+ test/ { print "PLAN " $3; inrun = 1; next }
        /^\[==========\] [0-9]+ test\(s\) run\./ { inrun = 0; next }
        !inrun { next }
        /^\[       OK \] / { print "PASS " pre substr($0, 14); next }
        /^\[  FAILED  \] / { print "FAIL " pre substr($0, 14); next }
        /^\[  SKIPPED \] / { print "SKIP " pre substr($0, 14); next }'
}

# hil_results <OUTPUT: the checks in make hil's output (hil/hil.sh prints the VM's result lines
# as "  [rig] PASS name: detail [t s]") as result lines named rig/name.
hil_results() {
    sed -nE 's/^  \[([a-z0-9]+)\] (PASS|FAIL|SKIP) ([^ :]+): *(.*)$/\2 \1\/\3 \4/p'
}
