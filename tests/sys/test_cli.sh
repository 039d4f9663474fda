#!/bin/sh
# The argil command line as a new user meets it: help, bad options and bad scripts give one
# clear line and a non-zero exit, never a crash.
set -eu
bin="$SAN/argil"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$bin" --help >"$tmp/h" || fail "--help exited non-zero"
grep -q sculpt "$tmp/h" || fail "--help does not list 'sculpt'"
"$bin" sculpt --help >"$tmp/h" || fail "sculpt --help exited non-zero"
for opt in --device --script --out --window --quiet --rate-hz; do
    grep -q -- "$opt" "$tmp/h" || fail "sculpt --help does not explain $opt"
done

expect_error() { # expected-status expected-text args...
    want=$1; text=$2; shift 2
    set +e
    "$bin" "$@" >"$tmp/o" 2>"$tmp/e"
    st=$?
    set -e
    [ "$st" = "$want" ] || fail "'$*' exited $st, want $want"
    grep -q -- "$text" "$tmp/e" || { cat "$tmp/e"; fail "'$*' did not say '$text'"; }
    [ "$(wc -l <"$tmp/e")" -le 2 ] || { cat "$tmp/e"; fail "'$*' printed more than a line or two of error"; }
}
expect_error 2 "unknown command 'frobnicate'" frobnicate
expect_error 2 "unknown option '--bogus'" sculpt --bogus
expect_error 2 "needs a value" sculpt --script
expect_error 2 "device 'usb': a scripted session runs on 'sim'" sculpt --device usb
expect_error 2 "--window must be" sculpt --window 99
expect_error 2 "--rate-hz needs 1000, 2000 or 4000" sculpt --rate-hz 3000
expect_error 2 "--rate-hz needs 1000, 2000 or 4000" sculpt --rate-hz
# At 4 kHz the board ticks four times a millisecond, the telemetry has a row per tick, and the
# session is as long in simulated time as at 1 kHz.
printf 'tool touch\nmove 0 0 36 0.3\nmove 0 0 32 0.2\n' >"$tmp/short.scn"
"$bin" sculpt --rate-hz 4000 --script "$tmp/short.scn" --out "$tmp/o4k" >"$tmp/s4k" 2>&1 ||
    { cat "$tmp/s4k"; fail "a 4 kHz session failed"; }
"$bin" sculpt --script "$tmp/short.scn" --out "$tmp/o1k" >"$tmp/s1k" 2>&1 ||
    { cat "$tmp/s1k"; fail "a 1 kHz session failed"; }
t4=$(sed -n 's/.*(\([0-9]*\) board ticks at 4000 Hz).*/\1/p' "$tmp/s4k")
t1=$(sed -n 's/.*(\([0-9]*\) board ticks at 1000 Hz).*/\1/p' "$tmp/s1k")
[ -n "$t4" ] && [ -n "$t1" ] || fail "the summaries do not say the loop rate: $(grep 'board ticks' "$tmp/s4k" "$tmp/s1k")"
s4=$(sed -n 's/^  simulated time *\([0-9.]*\) s.*/\1/p' "$tmp/s4k")
s1=$(sed -n 's/^  simulated time *\([0-9.]*\) s.*/\1/p' "$tmp/s1k")
echo "$s4 $s1 $t4 $t1" | awk '{ d = $1 - $2; if (d < 0) d = -d
    exit !(d <= 0.01 && $3 >= $1 * 4000 - 2 && $3 <= $1 * 4000 + 2 && $4 >= $2 * 1000 - 2 && $4 <= $2 * 1000 + 2) }' ||
    fail "4 kHz: $t4 ticks in $s4 s, 1 kHz: $t1 ticks in $s1 s (want the same time, four times the ticks)"
rows=$(($(wc -l <"$tmp/o4k/telemetry.csv") - 1))
[ "$rows" -ge $((t4 - 4)) ] && [ "$rows" -le "$t4" ] || fail "4 kHz telemetry has $rows rows for $t4 ticks"
grep -q '^  board state *ACTIVE' "$tmp/s4k" || { grep -i state "$tmp/s4k"; fail "the 4 kHz board did not end ACTIVE"; }
expect_error 1 "$tmp/none.scn: cannot open" sculpt --script "$tmp/none.scn" --out "$tmp/o1"
printf 'tool push\nmove 0 0 abc 1\n' >"$tmp/bad.scn"
expect_error 1 "bad.scn: line 2: 'move' arguments must be numbers" sculpt --script "$tmp/bad.scn" --out "$tmp/o2"
[ ! -e "$tmp/o2/final.ply" ] || fail "a refused script still wrote files"
# What only the B-spline model can do, asked of the springs: refused before the session starts,
# naming the script's line and why, and nothing written.
springs_refuse() { # name script-text expected-message
    printf "$2" >"$tmp/$1.scn"
    expect_error 1 "$1.scn: $3" sculpt --global-solve springs --script "$tmp/$1.scn" --out "$tmp/o-$1"
    [ ! -e "$tmp/o-$1/final.ply" ] || fail "the refused $1.scn still wrote files"
}
springs_refuse paint 'tool push\nmove 0 0 0 0.1\npaint stiffness 2 radius 10\n' \
    "line 3: 'paint' needs the B-spline model (--global-solve bspline); the springs' material is uniform"
springs_refuse undo 'tool push\nundo\n' \
    "line 2: 'undo' and 'redo' need the B-spline model (--global-solve bspline); the springs keep no history"
springs_refuse mirror 'tool carve\nmirror x\n' \
    "line 2: host tool settings need the B-spline model (--global-solve bspline); the springs only carve"
springs_refuse refine 'refine\n' \
    "line 1: 'refine' needs the B-spline model (--global-solve bspline); the springs have no knots"
echo "cli: all checks passed"
