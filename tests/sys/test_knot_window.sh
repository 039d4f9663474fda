#!/bin/sh
# Knot insertion from the command line and the live window (the session side is
# tests/sil/test_knot_refine.c): `argil sculpt --knot-ratio 2` with a script that refines once
# halves R and says so in the summary; the K key in the live window (scripted input under Xvfb)
# refines once, and a second K at R = 1 changes nothing; a bad --knot-ratio and a refine the
# session cannot do are refused with one clear line.
set -eu
rel="$REL/argil"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# 1. A script's refine (headless).
printf 'tool touch\nmove 0 0 36 0.4\nmove 0 0 32 0.3\nrefine\ntool push\npress 1\nmove 0 0 26 0.6\nrelease 1\nmove 0 0 45 0.3\n' >"$tmp/r.scn"
"$rel" sculpt --knot-ratio 2 --script "$tmp/r.scn" --out "$tmp/a" >"$tmp/a.txt" 2>&1 ||
    { cat "$tmp/a.txt"; fail "sculpt --knot-ratio 2 with a refine failed"; }
grep "knots" "$tmp/a.txt"
grep -q "knots               2 samples per knot span at the start, 1 at the end; 1 refinement" \
    "$tmp/a.txt" || fail "the summary does not show the refinement"
grep -q "watertight" "$tmp/a.txt" || fail "the mesh is not watertight after a refinement"

# 2. Refused before the start, one line each.
if "$rel" sculpt --script "$tmp/r.scn" --out "$tmp/b" 2>"$tmp/err"; then
    fail "a refine at R = 1 was accepted"
fi
cat "$tmp/err"
grep -q "r.scn: line 4: 'refine': already at one coefficient per sample" "$tmp/err" ||
    fail "refine at R = 1: wrong message"
[ "$(wc -l <"$tmp/err")" = 1 ] || fail "the refine error is not one line"
[ ! -e "$tmp/b/final.ply" ] || fail "a session ran despite the refused refine"
set +e
"$rel" sculpt --knot-ratio 3 --out "$tmp/b" 2>"$tmp/err"
st=$?
set -e
[ "$st" = 2 ] && grep -q "knot-ratio needs 1, 2 or 4" "$tmp/err" || fail "--knot-ratio 3: $st"

# 3. The K key in the live window: R 2 -> 1, then nothing (already one coefficient per sample).
command -v xvfb-run >/dev/null 2>&1 || fail "xvfb-run is missing (toolchain/install-deps.sh render)"
printf '0.8 key K\n1.2 key K\n2.0 key ESC\n' >"$tmp/keys.txt"
xvfb-run -a -s "-screen 0 1024x768x24" timeout 120 "$rel" sculpt --mouse --knot-ratio 2 \
    --input "$tmp/keys.txt" --out "$tmp/w" --width 480 --height 360 --linger 0 \
    >"$tmp/w.txt" 2>&1 || [ $? = 130 ] || { cat "$tmp/w.txt"; fail "the live window failed"; }
grep "knots" "$tmp/w.txt"
grep -q "knots               2 samples per knot span at the start, 1 at the end; 1 refinement" \
    "$tmp/w.txt" || { cat "$tmp/w.txt"; fail "K did not refine once"; }
echo "ok"
