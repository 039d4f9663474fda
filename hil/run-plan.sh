#!/bin/sh
# Runs the HIL plan: one check per line of the plan file whose rig column matches, one result
# line each ("PASS name: figure", "FAIL name: why", "SKIP name: why"), then "N passed, N failed"
# (and the skipped count). Exit 0 when nothing failed. The same script runs in the VM (hil/vm/init)
# and on a real board (hil/README.md).
# Usage: hil/run-plan.sh RIG_CONFIG PLAN TAGS OUT_DIR
#   TAGS (comma-separated) select the plan lines to run by their first column ("*" lines run
#   everywhere): the VM runs std or rt, a real board e.g. "std,board".
set -u
conf=$1 plan=$2 tags=$3 OUT=$4
HIL_DIR=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$OUT"
. "$conf"
[ -n "${BIN_DIR:-}" ] && PATH="$BIN_DIR:$PATH"
. "$HIL_DIR/lib.sh"
plan_pass=0 plan_fail=0 plan_skip=0 plan_n=0
rig_prepare || { echo "0 passed, 1 failed (rig $RIG_NAME: named lines missing)"; exit 1; }
# Variables of this loop are plan_*: the checks share the shell and use short names.
while read -r plan_rig plan_name plan_check plan_args; do
    case "$plan_rig" in ''|'#'*) continue ;; esac
    case ",$tags," in *",$plan_rig,"*) ;; *) [ "$plan_rig" = '*' ] || continue ;; esac
    plan_n=$((plan_n + 1))
    CHECK=$(printf '%02d-%s' "$plan_n" "$plan_name")
    RESULT=FAIL DETAIL="check_$plan_check did not report"
    plan_t0=$(hil-probe now)
    if command -v "check_$plan_check" >/dev/null 2>&1; then
        # shellcheck disable=SC2086
        "check_$plan_check" $plan_args </dev/null
    else
        DETAIL="unknown check '$plan_check' in $plan"
    fi
    rig_cleanup
    case "$RESULT" in
    PASS) plan_pass=$((plan_pass + 1)) ;;
    SKIP) plan_skip=$((plan_skip + 1)) ;;
    *) plan_fail=$((plan_fail + 1)) ;;
    esac
    printf '%s %s: %s [%s s]\n' "$RESULT" "$plan_name" "$DETAIL" \
        "$(awk -v a="$plan_t0" -v b="$(hil-probe now)" 'BEGIN { printf "%.1f", b - a }')"
done <"$plan"
echo "$plan_pass passed, $plan_fail failed, $plan_skip skipped ($tags on rig $RIG_NAME)"
[ "$plan_fail" = 0 ]
