#!/bin/sh
# Painted colour end to end (issue 5, `action paint`): the live window under Xvfb shows a red
# stroke where the script paints (and no red before it), the window and a headless run write the
# same model.argil, `argil info` reports the painted colour and `argil mesh` exports it as vertex
# colours; then a painting session killed with SIGKILL mid-stroke is recovered by `argil recover`
# byte for byte as the model at its last journal record (colour records after a checkpoint whose
# base already holds colour). The GL run uses the release build, as tests/sys/test_sculpt_window.sh.
set -eu
rel="$REL/argil"
tmp=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
command -v xvfb-run >/dev/null 2>&1 || fail "xvfb-run is missing (toolchain/install-deps.sh render)"
py=/usr/bin/python3

# "red PNG": pixels below the HUD that are the paint's red (lit or in shade), their mean x and y.
cat >"$tmp/png.py" <<'PY'
import sys
from pngread import load
HUD_ROWS = 60
def red(p): return p[0] > 90 and p[1] * 10 < p[0] * 4 and p[2] * 10 < p[0] * 4
w, h, px = load(sys.argv[2])
pts = [(x, y) for y in range(HUD_ROWS, h) for x in range(w) if red(px[y][x])]
n = len(pts)
print(n, sum(x for x, _ in pts) // max(n, 1), sum(y for _, y in pts) // max(n, 1))
PY
redpx() { PYTHONPATH=tests/sys "$py" "$tmp/png.py" red "$1"; }

# 1. A stroke across the front of the clay (the camera looks at it from +z), 2 mm deep, red.
cat >"$tmp/paint.scn" <<'EOF'
set radius_mm 4
tool touch
move 0 0 45 0.5
move -9 0 36 0.4
tool carve
action paint rgb 230 20 20
press 1
move -9 0 27.6 0.2
move 0 0 27.4 0.5
move 9 0 27.6 0.5
release 1
move 0 0 45 0.4
EOF
xvfb-run -a -s "-screen 0 1024x768x24" "$rel" sculpt --script "$tmp/paint.scn" --out "$tmp/live" \
    --fast --width 480 --height 360 --screenshot-every 500 --screenshot "$tmp/last.png" \
    --linger 0 >"$tmp/live.txt" 2>&1 || { cat "$tmp/live.txt"; fail "live sculpt failed"; }
grep -q "live window .* frames" "$tmp/live.txt" || fail "no window ran"
"$rel" sculpt --script "$tmp/paint.scn" --out "$tmp/head" --headless --quiet ||
    fail "headless sculpt failed"
cmp "$tmp/live/model.argil" "$tmp/head/model.argil" ||
    fail "model.argil differs between the window and --headless"
first=$(ls "$tmp/live/frames" | head -n 1)
set -- $(redpx "$tmp/live/frames/$first")
echo "first frame ($first): $1 red pixels"
[ "$1" -le 5 ] || fail "red on screen before anything was painted ($1 pixels)"
set -- $(redpx "$tmp/last.png")
echo "last frame: $1 red pixels, centred at x $2 y $3 (of 480 x 360)"
[ "$1" -ge 300 ] || fail "the painted stroke does not show ($1 red pixels)"
# on the clay, which the default view shows in the middle of the window
[ "$2" -ge 120 ] && [ "$2" -le 360 ] && [ "$3" -ge 100 ] && [ "$3" -le 300 ] ||
    fail "the red is not on the clay (centred at $2, $3)"

# 2. What was kept: the model's colour, and a coloured mesh export.
"$rel" info "$tmp/head/model.argil" >"$tmp/info.txt" || fail "argil info failed"
cat "$tmp/info.txt"
grep -q "colours painted" "$tmp/info.txt" || fail "argil info: no painted colours"
n=$(sed -n 's/.*colour    painted on \([0-9]*\) samples (230 20 20 on \([0-9]*\) of them).*/\1 \2/p' \
    "$tmp/info.txt")
[ -n "$n" ] || fail "argil info names no 230 20 20 paint"
set -- $n
echo "painted samples: $1, of them 230 20 20: $2"
# a 4 mm ball 2 mm deep drawn over 18 mm: a few hundred samples (the SIL test measured ~800)
[ "$1" -ge 300 ] && [ "$1" -le 3000 ] && [ "$2" = "$1" ] || fail "unexpected painted sample count"
"$rel" mesh "$tmp/head/model.argil" -o "$tmp/painted.ply" >/dev/null || fail "argil mesh failed"
"$rel" info "$tmp/painted.ply" | grep -q "colours yes" || fail "the exported mesh has no colours"
# an unpainted session's model has no colour section (the file as before)
"$rel" sculpt --script scripts/default.scn --out "$tmp/plain" --headless --quiet ||
    fail "default sculpt failed"
"$rel" info "$tmp/plain/model.argil" | grep -q "colours none" || fail "an unpainted model has colour"

# 3. Crash: paint back and forth (two colours) for ~6 s with a checkpoint every 1.5 s, kill -9
#    once the journal was rotated twice (the base then holds colour) and holds records after it.
cat >"$tmp/long.scn" <<'EOF'
set radius_mm 4
tool touch
move 0 0 45 0.5
move -9 0 36 0.4
tool carve
action paint rgb 230 20 20
press 1
move -9 0 27.6 0.2
move 9 0 27.6 1.5
action soft-paint rgb 40 60 220 strength 30
move -9 0 27.6 1.5
move 9 0 27.6 1.5
action paint rgb 20 200 40
move -9 0 27.6 1.5
release 1
move 0 0 45 0.4
wait 2
EOF
attempt=0
while :; do
    attempt=$((attempt + 1))
    rm -rf "$tmp/s"
    "$rel" sculpt --device sim --script "$tmp/long.scn" --out "$tmp/s" --quiet \
        --autosave-s 0.2 --checkpoint-s 1.5 &
    pid=$!
    polls=0
    while :; do
        # the size after the rotation is seen complete (else it may be the old journal's)
        if [ -e "$tmp/s/journal-base-2.argil" ] && [ ! -e "$tmp/s/journal-base-1.argil" ]; then
            size=$(stat -c %s "$tmp/s/journal.log" 2>/dev/null || echo 0)
            [ "$size" -gt 3000 ] && break
        fi
        kill -0 "$pid" 2>/dev/null || fail "the session ended before its journal held records"
        polls=$((polls + 1))
        [ "$polls" -lt 6000 ] || fail "no journal records after 60 s"
        sleep 0.01
    done
    kill -9 "$pid"
    status=0
    wait "$pid" || status=$?
    pid=
    [ "$status" = 137 ] || fail "the session was not killed in the middle (exit $status)"
    "$rel" recover "$tmp/s" -o "$tmp/rec.argil" >"$tmp/rec.txt" ||
        { cat "$tmp/rec.txt"; fail "recover failed"; }
    cat "$tmp/rec.txt"
    replayed=$(sed -n 's/.*painted colour *\([0-9]*\) samples replayed.*/\1/p' "$tmp/rec.txt")
    [ -n "$replayed" ] || fail "recover says nothing about painted colour"
    [ "$replayed" -gt 0 ] && break
    echo "attempt $attempt: no colour record after the rotation; again"
    [ "$attempt" -lt 3 ] || fail "3 kills in a row left no colour record after the rotation"
done
grep -q "the model holds painted colour" "$tmp/rec.txt" || fail "the recovered model holds no colour"
last=$(sed -n 's/.*journal records *[0-9]* (numbers [0-9]*\.\.\([0-9]*\)).*/\1/p' "$tmp/rec.txt")
[ -n "$last" ] || fail "cannot read the last record number"
"$rel" sculpt --device sim --script "$tmp/long.scn" --out "$tmp/ref" --quiet \
    --debug-journal-dump "$last" "$tmp/ref.argil"
cmp "$tmp/ref.argil" "$tmp/rec.argil" || fail "the recovered model differs from record $last"
"$rel" info "$tmp/rec.argil" | grep "colour  " || fail "argil info: no colour in the recovered model"
echo "recovered model = model at journal record $last, byte for byte, with $replayed colour" \
    "samples replayed after the checkpoint ($(stat -c %s "$tmp/rec.argil") bytes)"
