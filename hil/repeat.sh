#!/bin/sh
# make hil-repeat N=20: runs the whole HIL plan N times, one run after another, and says for each
# check how many runs it passed; keeps each run's output and logs under $(BUILD)/hil/repeat/.
# A check is reliable when it passes N of N; the table names every run a check failed in, so its
# logs can be read (run-K-<rig>/logs/). Nothing else should run on the machine meanwhile: the VM
# is emulated (TCG) and a loaded machine is a different rig (docs: hil/README.md).
# Usage: hil/repeat.sh N BUILD_DIR
set -u
n=${1:?usage: hil/repeat.sh N BUILD_DIR}
build=${2:?usage: hil/repeat.sh N BUILD_DIR}
case "$n" in '' | *[!0-9]*) echo "hil-repeat: N must be a whole number, got '$n'" >&2; exit 2 ;; esac
[ "$n" -ge 1 ] || { echo "hil-repeat: N must be at least 1" >&2; exit 2; }
dir="$build/hil/repeat"
rm -rf "$dir"
mkdir -p "$dir"
runs_failed=0
i=1
while [ "$i" -le "$n" ]; do
    start=$(date +%s)
    st=0
    make --no-print-directory hil >"$dir/run-$i.out" 2>&1 || st=$?
    secs=$(($(date +%s) - start))
    for rig in std rt; do
        [ -d "$build/hil/run-$rig" ] && cp -r "$build/hil/run-$rig" "$dir/run-$i-$rig"
    done
    # one line per check and run: "K name PASS|FAIL|SKIP"
    sed -n "s/^  \[\([a-z]*\)\] \(PASS\|FAIL\|SKIP\) \([a-z0-9-]*\):.*/$i \3 \2/p" "$dir/run-$i.out" >>"$dir/results"
    sum=$(grep -E '^[0-9]+ passed, [0-9]+ failed' "$dir/run-$i.out" | tail -n 1)
    [ "$st" = 0 ] || runs_failed=$((runs_failed + 1))
    echo "hil-repeat: run $i of $n: ${sum:-no summary (status $st)} in $secs s (load $(cut -d' ' -f1-3 /proc/loadavg))"
    i=$((i + 1))
done
echo "hil-repeat: $n runs, $runs_failed with a failure; per check (passed of runs, the runs it failed in):"
awk -v n="$n" '
    { seen[$2] = 1; if ($3 == "PASS") pass[$2]++; else if ($3 == "FAIL") fails[$2] = fails[$2] " " $1
      else skips[$2]++ }
    END { for (c in seen) printf "  %-28s %3d of %d%s%s\n", c, pass[c], n,
                                  fails[c] != "" ? "  failed in run" fails[c] : "",
                                  skips[c] ? "  skipped " skips[c] : "" }' "$dir/results" | sort
[ "$runs_failed" = 0 ]
