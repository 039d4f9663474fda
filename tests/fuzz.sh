#!/bin/sh
# make fuzz / make fuzz-long: runs libFuzzer targets one at a time and prints one row per target.
# A crash, leak, timeout or out-of-memory input is copied into tests/fuzz/corpus/<target>/ as
# crash-<sha1> (a regression seed every later run replays); the other targets still run, then
# the run fails.
# Usage: tests/fuzz.sh FZ_DIR seconds S TARGET...       each target for S seconds
#        tests/fuzz.sh FZ_DIR runs N MAX_S TARGET...    each target to N executions, cut at MAX_S
# The table (markdown) is also written to FZ_DIR/fuzz-<mode>.md, a row as each target ends.
set -u
fz=$1
mode=$2
case "$mode" in
    seconds) limit=$3; shift 3; flags="-max_total_time=$limit" ;;
    runs) limit=$3; max_s=$4; shift 4; flags="-runs=$limit -max_total_time=$max_s" ;;
    *) echo "fuzz.sh: mode must be 'seconds' or 'runs'" >&2; exit 2 ;;
esac
table="$fz/fuzz-$mode.md"
mkdir -p "$fz"
{
    echo "| target | executions | seconds | exec/s | new units | result |"
    echo "|---|---:|---:|---:|---:|---|"
} >"$table"
cat "$table"

failed=""
for t in "$@"; do
    corpus="$fz/corpus/$t"
    artifacts="$fz/artifacts/$t"
    log="$fz/$t.log"
    mkdir -p "$corpus" "$artifacts"
    seeds=tests/fuzz/corpus/$t
    [ -d "$seeds" ] || seeds=
    start=$(date +%s)
    # shellcheck disable=SC2086 # flags and seeds are word lists
    "$fz/$t" $flags -print_final_stats=1 -artifact_prefix="$artifacts/" "$corpus" $seeds >"$log" 2>&1
    st=$?
    end=$(date +%s)
    runs=$(sed -n 's/^stat::number_of_executed_units: *\([0-9]*\).*/\1/p' "$log" | tail -n 1)
    new=$(sed -n 's/^stat::new_units_added: *\([0-9]*\).*/\1/p' "$log" | tail -n 1)
    secs=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$log" | tail -n 1)
    runs=${runs:-0}
    new=${new:-0}
    secs=${secs:-$((end - start))}
    rate=$(awk -v r="$runs" -v s="$secs" 'BEGIN { if (s > 0) printf "%d", r / s; else print "-" }')
    unit=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$log" | tail -n 1)
    if [ "$st" != 0 ] || [ -n "$unit" ]; then
        result="FAILED (exit $st)"
    elif [ "$mode" = runs ] && [ "$runs" -lt "$limit" ]; then
        result="stopped at the ${max_s} s cap before $limit"
    else
        result=done
    fi
    row="| $t | $runs | $secs | $rate | $new | $result |"
    echo "$row" >>"$table"
    echo "$row"
    case "$result" in FAILED*) ;; *) continue ;; esac

    failed="$failed $t"
    tail -n 40 "$log"
    echo "fuzz: $t FAILED (log: $log)"
    if [ -n "$unit" ] && [ -f "$unit" ]; then
        seed=
        for f in tests/fuzz/corpus/"$t"/*; do
            if [ -f "$f" ] && cmp -s "$unit" "$f"; then seed=$f; fi
        done
        if [ -n "$seed" ]; then
            echo "fuzz: reproducer $unit is already the seed $seed"
        else
            seed="tests/fuzz/corpus/$t/crash-$(sha1sum "$unit" | cut -d' ' -f1)"
            mkdir -p "tests/fuzz/corpus/$t"
            cp "$unit" "$seed"
            echo "fuzz: reproducer $unit, copied to $seed"
        fi
        echo "fuzz: reproduce with $fz/$t $seed; fix the bug, then commit the seed"
    else
        echo "fuzz: no reproducer was written (see the log)"
    fi
done
echo "fuzz: table in $table"
if [ -n "$failed" ]; then
    echo "fuzz: FAILED:$failed"
    exit 1
fi
