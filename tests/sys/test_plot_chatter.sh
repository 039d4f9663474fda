#!/bin/sh
# argil plot --chatter on synthetic telemetry: a contact that buzzes (a 100 Hz +-0.5 N square
# wave) fails the goal with exit 1 and its figure, a quiet one (+-0.02 N ripple) passes with 0,
# at 1 and 4 kHz; a first contact's step is forgiven, the same step in contact is not; the
# chart of the buzzing log has the chatter panel's goal line and says the figure on stdout;
# usage errors and a malformed log exit 2 with one line.
set -eu
bin="$SAN/argil"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
. tests/sys/expect_one_line_error.sh

# telemetry RATE_HZ SECONDS AWK_FORCE > file: rows as session.c writes them (time_s to the
# millisecond); AWK_FORCE sets fx fy fz and c (the contact flag) from i (row) and t (seconds).
telemetry() {
    awk -v rate="$1" -v secs="$2" 'BEGIN {
        print "time_s,x_mm,y_mm,z_mm,fx_n,fy_n,fz_n,force_n,state,tool,buttons,contact,sculpting"
        n = rate * secs
        for (i = 0; i < n; i++) {
            t = (i + 1) / rate
            '"$3"'
            printf "%.3f,0,0,20,%.4f,%.4f,%.4f,%.4f,ACTIVE,1,0,%d,0\n", t, fx, fy, fz,
                   sqrt(fx * fx + fy * fy + fz * fz), c
        }
    }'
}
half_period() { echo "int(t * 200) % 2"; } # 0 or 1, flipping every 5 ms: 100 Hz

for rate in 1000 4000; do
    telemetry $rate 2 "fx = ($(half_period)) ? -0.5 : 0.5; fy = 0; fz = 1; c = 1" >"$tmp/buzz$rate.csv"
    telemetry $rate 2 "fx = 0; fy = ($(half_period)) ? -0.02 : 0.02; fz = 0.5; c = 1" >"$tmp/quiet$rate.csv"
    st=0
    "$bin" plot "$tmp/buzz$rate.csv" --chatter >"$tmp/out" || st=$?
    echo "buzz at $rate Hz: exit $st: $(cat "$tmp/out")"
    [ "$st" = 1 ] || fail "a buzzing contact at $rate Hz passed (exit $st)"
    grep -Eq "^force above 50 Hz: 0\.(49|50|51)[0-9] N RMS over $((rate * 2)) ticks in contact, [1-9][0-9]* steps > 0\.2 N" "$tmp/out" ||
        fail "buzz figure at $rate Hz: $(cat "$tmp/out")"
    [ "$(wc -l <"$tmp/out")" = 1 ] || fail "--chatter printed more than the figure"
    st=0
    "$bin" plot "$tmp/quiet$rate.csv" --chatter >"$tmp/out" || st=$?
    echo "quiet at $rate Hz: exit $st: $(cat "$tmp/out")"
    [ "$st" = 0 ] || fail "a quiet contact at $rate Hz failed the goal (exit $st)"
    grep -Eq "^force above 50 Hz: 0\.0(19|20|21) N RMS over $((rate * 2)) ticks in contact, 0 steps" "$tmp/out" ||
        fail "quiet figure at $rate Hz: $(cat "$tmp/out")"
done

# A 1 N first contact at 0.5 s, held steady: forgiven. The same 1 N step at 0.5 s from 0.1 N
# already in contact: one step, the goal missed.
telemetry 1000 1 "fx = 0; fy = 0; fz = (t > 0.5) ? 1 : 0; c = (t > 0.5)" >"$tmp/touch.csv"
telemetry 1000 1 "fx = 0; fy = 0; fz = (t > 0.5) ? 1.1 : 0.1; c = 1" >"$tmp/jump.csv"
st=0
"$bin" plot "$tmp/touch.csv" --chatter >"$tmp/out" || st=$?
echo "first contact: exit $st: $(cat "$tmp/out")"
grep -q "0 steps > 0.2 N (+1 on first contact" "$tmp/out" || fail "first contact: $(cat "$tmp/out")"
st=0
"$bin" plot "$tmp/jump.csv" --chatter >"$tmp/out" || st=$?
echo "step in contact: exit $st: $(cat "$tmp/out")"
[ "$st" = 1 ] && grep -q " 1 steps > 0.2 N (+0 on first contact" "$tmp/out" ||
    fail "a step in contact was not counted (exit $st): $(cat "$tmp/out")"

# The chart: the figure on stdout, and the chatter panel's goal line (0 160 70) across it.
"$bin" plot "$tmp/buzz1000.csv" -o "$tmp/buzz.png" --width 900 --height 500 >"$tmp/out" ||
    fail "plot of the buzzing log failed"
grep -q "^force above 50 Hz: 0.4[0-9]* N RMS over 2000 ticks" "$tmp/out" || fail "plot did not print the figure"
run=$(PYTHONPATH=tests/sys /usr/bin/python3 - "$tmp/buzz.png" <<'PY'
import sys
from pngread import load
w, h, rows = load(sys.argv[1])
best = 0
for r in rows:
    run = 0
    for p in r:
        run = run + 1 if p == (0, 160, 70) else 0
        best = max(best, run)
print(best)
PY
)
echo "plot: the goal line runs $run pixels of 900"
[ "$run" -ge 700 ] || fail "no goal line across the chatter panel ($run pixels)"

# Refusals: one line, exit 2.
expect_error 2 "writes no image" plot "$tmp/buzz1000.csv" --chatter -o "$tmp/x.png"
head -n 3 "$tmp/quiet1000.csv" >"$tmp/bad.csv"
echo "0.004,0,0,20,0,0,0,0,ACTIVE,1,0,2,0" >>"$tmp/bad.csv"
expect_error 2 "bad.csv: line 4: contact is not 0 or 1" plot "$tmp/bad.csv" --chatter
echo "plot --chatter: all checks passed"
