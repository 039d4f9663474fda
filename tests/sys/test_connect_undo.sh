#!/bin/sh
# `argil connect`'s undo and redo (--undo-mb, command lines on standard input), on the in-process
# sim board:
#   1. --help explains --undo-mb and the stdin commands; a bad --undo-mb is one line, exit 2;
#   2. a B-spline session: 'undo' and 'redo' with nothing recorded are refused, one line each on
#      stderr, a line that is no command is named, blanks and CR around a command are taken, and
#      the session runs on to --seconds and ends cleanly (exit 0) with the summary's undo line;
#      standard input closed at once does not end it early;
#   3. with the springs solve (connect's default) and with --undo-mb 0 a request is refused with
#      the reason, and the summary says undo is off.
# The sim board's hand holds the stylus still above the clay with no button pressed
# (host/link/link_sim.c), so no stroke happens here: undo of real strokes, the press in the air
# and the sliced diff are tested through the same module in tests/unit/test_session_undo.c and
# the lockstep session in tests/sil/test_session_undo.c.
set -eu
bin="$REL/argil"
san="$SAN/argil"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# 1. Help and bad values.
"$san" connect --help >"$tmp/help" || fail "--help exits non-zero"
grep -q -- "--undo-mb N" "$tmp/help" || fail "--help does not explain --undo-mb"
grep -q "'undo' or 'redo'" "$tmp/help" || fail "--help does not say how to ask for undo and redo"
for v in x -1 65537 ""; do
    st=0
    timeout 20 "$san" connect --device sim --seconds 1 --out "$tmp/bad" --undo-mb "$v" \
        >"$tmp/out" 2>"$tmp/err" </dev/null || st=$?
    [ "$st" = 124 ] && fail "--undo-mb '$v' hung (20 s)"
    [ "$st" = 2 ] || fail "--undo-mb '$v': exit $st, want 2: $(cat "$tmp/err")"
    [ "$(wc -l <"$tmp/err")" = 1 ] || fail "--undo-mb '$v' printed $(wc -l <"$tmp/err") lines"
    grep -q "^argil connect: --undo-mb needs MiB 0..65536 (0: no undo)$" "$tmp/err" ||
        fail "--undo-mb '$v' said: $(cat "$tmp/err")"
    [ ! -e "$tmp/bad" ] || fail "--undo-mb '$v' wrote $tmp/bad"
done
echo "ok: --undo-mb x, -1, 65537 and '' refused, one line each"

# 2. Commands on standard input, B-spline model (the ASan build).
{ sleep 1; echo "undo"; printf '  redo \r\n'; echo "bogus 12"; echo; sleep 0.5; } |
    "$san" connect --device sim --seconds 5 --arm --global-solve bspline --out "$tmp/b" \
        >"$tmp/b.out" 2>"$tmp/b.err" || fail "session exit $?: $(tail -n 3 "$tmp/b.err")"
cat "$tmp/b.err"
grep -q "^argil connect: undo refused: nothing to undo (undo 0 | redo 0)$" "$tmp/b.err" ||
    fail "no refusal of the undo"
grep -q "^argil connect: redo refused: nothing to redo (undo 0 | redo 0)$" "$tmp/b.err" ||
    fail "no refusal of the redo (blanks and CR around it)"
grep -q "^argil connect: stdin: 'bogus 12' is no command (undo, redo)$" "$tmp/b.err" ||
    fail "the bad line is not named"
[ "$(grep -c "^argil connect: " "$tmp/b.err")" = 3 ] || fail "more than the 3 lines (the blank line is no command)"
grep -q "^  undo                0 strokes recorded (0 undone, 0 redone, 2 refused), 0.0 KiB held of 256 MiB; recording CPU time per tick median " \
    "$tmp/b.out" || fail "summary: $(grep '^  undo' "$tmp/b.out")"
grep -q "^argil connect: sim for [5-9]\.[0-9] s$" "$tmp/b.out" || fail "the session did not run to --seconds"
[ -s "$tmp/b/model.argil" ] || fail "no model.argil"
echo "ok: undo and redo asked on stdin, refused with nothing recorded; the session ran on"

"$bin" connect --device sim --seconds 2 --global-solve bspline --out "$tmp/n" \
    >"$tmp/n.out" 2>"$tmp/n.err" </dev/null || fail "stdin at its end: exit $?"
grep -q "^argil connect: sim for [2-9]\.[0-9] s$" "$tmp/n.out" || fail "stdin at its end ended the session"

# 3. Off: the springs solve, --undo-mb 0.
echo undo | "$bin" connect --device sim --seconds 1.5 --out "$tmp/s" >"$tmp/s.out" 2>"$tmp/s.err" ||
    fail "springs session exit $?"
grep -q "^argil connect: undo refused: undo needs the B-spline model (--global-solve bspline)" "$tmp/s.err" ||
    fail "springs: $(cat "$tmp/s.err")"
grep -q "^  undo                undo needs the B-spline model" "$tmp/s.out" || fail "springs summary"
echo redo | "$bin" connect --device sim --seconds 1.5 --global-solve bspline --undo-mb 0 \
    --out "$tmp/z" >"$tmp/z.out" 2>"$tmp/z.err" || fail "--undo-mb 0 session exit $?"
grep -q "^argil connect: redo refused: undo off (--undo-mb 0)" "$tmp/z.err" || fail "--undo-mb 0: $(cat "$tmp/z.err")"
grep -q "^  undo                undo off (--undo-mb 0)$" "$tmp/z.out" || fail "--undo-mb 0 summary"
echo "ok: springs and --undo-mb 0 refuse with the reason"
