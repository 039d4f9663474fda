# The test runner's counting: runs one test under a time limit, counts every check it reports
# and prints one line for it ("ok   name (N tests)", "FAIL name ... — log: ..." with the log's
# tail, "SKIP ..."); run_summary ends with "N passed, N failed, N skipped". Sourced by
# tests/run_all.sh (the tiers) and tests/runner/test_runner.sh (its own test).
#   run_init LOG_DIR           counters to zero; logs go to LOG_DIR/NAME.log
#   run_test cmocka|script PATH SECONDS [live]
#       cmocka: an executable; every cmocka test is counted (tests/lib/report.sh, cmocka_results);
#               one that crashes or times out after "Running N test(s)" has its unrun tests
#               failed; without that line, a non-zero exit is one failed test.
#       script: run with sh and RESULTS_FILE=LOG_DIR/NAME.results: the checks it reports there
#               (tests/lib/report.sh) are counted; reporting nothing, it is one test (exit 0
#               passes, 77 skips, anything else fails).
#   run_timeout NAME DEFAULT   the time limit of NAME in seconds: $TEST_TIMEOUT_<NAME> (dashes as
#                              underscores), else $TEST_TIMEOUT, else DEFAULT
#   run_summary                the summary line; status 0 when nothing failed
# A test's output also shows as it runs (the log is still written) with TEST_LIVE=1, or when
# run_test is given "live" and TEST_LIVE is not 0.
# Counters: run_passed run_failed run_skipped; run_failed_names lists what failed.
# Paths are from the top of the tree (the Makefile's directory).
. tests/lib/report.sh

run_init() {
    run_log_dir=$1
    mkdir -p "$run_log_dir"
    run_passed=0 run_failed=0 run_skipped=0 run_failed_names=""
}

run_timeout() {
    run_tv=$(echo "$1" | tr -c 'A-Za-z0-9_\n' '_')
    eval "run_tv=\${TEST_TIMEOUT_$run_tv:-\${TEST_TIMEOUT:-$2}}"
    echo "$run_tv"
}

# run_count RESULTS STATUS: sets rc_p rc_f rc_s (and rc_unrun, rc_bad) from the result lines and
# the exit status, by the rules above.
run_count() {
    read -r rc_p rc_f rc_s rc_plan rc_bad <<EOF
$(awk '
        $1 == "PASS" && NF >= 2 { p++; next }
        $1 == "FAIL" && NF >= 2 { f++; next }
        $1 == "SKIP" && NF >= 2 { s++; next }
        $1 == "PLAN" && $2 ~ /^[0-9]+$/ && NF == 2 { plan += $2; next }
        NF { bad++ }
        END { printf "%d %d %d %d %d\n", p, f, s, plan, bad }' "$1")
EOF
    rc_unrun=$((rc_plan - rc_p - rc_f - rc_s))
    [ "$rc_unrun" -gt 0 ] || rc_unrun=0
    rc_f=$((rc_f + rc_unrun + rc_bad))
    if [ $((rc_p + rc_f + rc_s)) = 0 ]; then
        case "$2" in
        0) rc_p=1 ;;
        77) rc_s=1 ;;
        *) rc_f=1 ;;
        esac
    elif [ "$2" != 0 ] && [ "$rc_f" = 0 ]; then
        rc_f=1 # it ended badly after its checks (a sanitizer's report at exit, a failed step)
    fi
}

# run_exec SECONDS LOG CMD...: runs CMD in its own process group under timeout, output to LOG
# (and to the terminal with TEST_LIVE=1); sets run_st (124: timed out) and run_secs.
run_exec() {
    run_lim=$1 run_lg=$2
    shift 2
    run_t0=$(date +%s)
    if [ "$run_live" = 1 ]; then
        { run_st=0; timeout -k 10 "$run_lim" "$@" 2>&1 </dev/null || run_st=$?; echo "$run_st" >"$run_lg.status"; } |
            tee "$run_lg"
        run_st=$(cat "$run_lg.status")
        rm -f "$run_lg.status"
    else
        run_st=0
        timeout -k 10 "$run_lim" "$@" >"$run_lg" 2>&1 </dev/null || run_st=$?
    fi
    run_secs=$(($(date +%s) - run_t0))
    # timeout: 124 after TERM; 137 when the test outlived TERM by the -k grace and got KILL.
    if [ "$run_st" = 137 ] && [ "$run_secs" -ge "$run_lim" ]; then run_st=124; fi
}

run_test() {
    run_kind=$1 run_path=$2 run_lim=$3 run_live=${TEST_LIVE:-}
    if [ -z "$run_live" ] && [ "${4:-}" = live ]; then run_live=1; fi
    case "$run_kind" in
    script) run_name=$(basename "$run_path" .sh) ;;
    *) run_name=$(basename "$run_path") ;;
    esac
    run_log="$run_log_dir/$run_name.log"
    run_res="$run_log_dir/$run_name.results"
    : >"$run_res"
    if [ "$run_kind" = script ]; then
        run_exec "$run_lim" "$run_log" env RESULTS_FILE="$run_res" sh "$run_path"
    else
        run_exec "$run_lim" "$run_log" "$run_path"
        cmocka_results "" <"$run_log" >"$run_res"
    fi
    run_count "$run_res" "$run_st"
    run_passed=$((run_passed + rc_p))
    run_failed=$((run_failed + rc_f))
    run_skipped=$((run_skipped + rc_s))
    run_print
}

# One line for the test just run, then what a person needs: failed checks and the log's tail,
# skipped checks with their reason.
run_print() {
    run_what="$rc_p passed, $rc_f failed"
    [ "$rc_s" = 0 ] || run_what="$run_what, $rc_s skipped"
    if [ "$run_st" -gt 128 ] && [ "$run_st" != 124 ]; then
        run_how="killed by signal $((run_st - 128))"
    else
        run_how="exit status $run_st"
    fi
    if [ "$rc_f" != 0 ]; then
        run_failed_names="$run_failed_names $run_name"
        if [ "$run_st" = 124 ]; then
            echo "FAIL $run_name ($run_what) — timed out after $run_lim s — log: $run_log"
        else
            echo "FAIL $run_name ($run_what) — log: $run_log"
        fi
        [ "$run_kind" = cmocka ] || run_lines FAIL | head -n 20
        [ "$rc_unrun" = 0 ] || echo "    $rc_unrun planned test(s) never reported ($run_how)"
        [ "$rc_bad" = 0 ] || echo "    $rc_bad unreadable line(s) in $run_res"
        if [ "$run_kind" = cmocka ] && [ "$run_st" != 124 ] && [ "$rc_unrun" = 0 ]; then
            grep -E '^\[  (FAILED|ERROR) |ERROR|error|Sanitizer|runtime error' "$run_log" | head -n 20 | sed 's/^/    /'
        else
            tail -n 20 "$run_log" | sed 's/^/    /'
        fi
    elif [ "$rc_s" != 0 ] && [ "$rc_p" = 0 ] && [ ! -s "$run_res" ]; then
        echo "SKIP $run_name: $(grep -v '^[[:space:]]*$' "$run_log" | tail -n 1)"
    elif [ ! -s "$run_res" ]; then
        echo "ok   $run_name"
    else
        run_n="$rc_p checks"
        [ "$run_kind" != cmocka ] || run_n="$rc_p tests"
        [ "$rc_s" = 0 ] || run_n="$run_n, $rc_s skipped"
        echo "ok   $run_name ($run_n)"
    fi
    run_lines SKIP | head -n 40
}

# run_lines PASS|FAIL|SKIP: the test's result lines of that kind, indented, as "SKIP name: why".
run_lines() {
    awk -v k="$1" '$1 == k { n = $2; $1 = $2 = ""; sub(/^ +/, ""); print "    " k " " n ($0 == "" ? "" : ": " $0) }' "$run_res"
}

run_summary() {
    echo
    [ -z "$run_failed_names" ] || echo "failed:$run_failed_names"
    echo "$run_passed passed, $run_failed failed, $run_skipped skipped"
    [ "$run_failed" = 0 ]
}
