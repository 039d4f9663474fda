#!/bin/sh
# The live sculpting window under Xvfb: `argil sculpt` with a display shows the session being
# sculpted (screenshots: the clay lit, the tool, the dent appearing) and writes the very same
# files as a headless run; `argil sculpt --mouse` with scripted input sculpts with the mouse
# (push, Shift inverts to pull), and the keyboard panel changes the tool's parameters. The GL
# runs use the release build (Mesa's JIT leaves allocations LeakSanitizer cannot attribute).
set -eu
rel="$REL/argil"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
command -v xvfb-run >/dev/null 2>&1 || fail "xvfb-run is missing (toolchain/install-deps.sh render)"
xvfb() { xvfb-run -a -s "-screen 0 1024x768x24" "$@"; }
py=/usr/bin/python3

# Pixel classes of a window screenshot below the HUD band (HUD_ROWS rows):
#   "stats PNG": W H CLAY_SHARE TOOL_PX CLAY_LUMA_P5 CLAY_LUMA_P95
#   "diff A B [X0 Y0 X1 Y1]": pixels that are clay in both and differ by > 25 levels of luma
#   "wire PNG": pixels of the second iso-surface's wire colour (magenta) below the HUD
#   "legend PNG": RGB at the left and right ends of the colour legend (row 50, x 8 and 188)
cat >"$tmp/png.py" <<'PY'
import sys
from pngread import load, wire
HUD_ROWS = 60  # the HUD's four lines and the colour legend under them
def clay(p): return p[0] > p[2] + 25 and p[0] >= p[1]
def tool(p): return p[2] > p[0] + 20 and p[1] > p[0] + 10 and not (p[1] > p[0] + 60 and p[1] > p[2] + 60)
def luma(p): return (299 * p[0] + 587 * p[1] + 114 * p[2]) // 1000
if sys.argv[1] == 'wire':
    w, h, px = load(sys.argv[2])
    print(sum(1 for row in px[HUD_ROWS:] for p in row if wire(p)))
elif sys.argv[1] == 'legend':
    w, h, px = load(sys.argv[2])
    print(*px[50][8], *px[50][188])
elif sys.argv[1] == 'stats':
    w, h, px = load(sys.argv[2])
    body = [p for row in px[HUD_ROWS:] for p in row]
    c = sorted(luma(p) for p in body if clay(p))
    t = sum(1 for p in body if tool(p))
    p5 = c[len(c) // 20] if c else 0
    p95 = c[len(c) * 19 // 20] if c else 0
    print(w, h, round(len(c) / len(body), 3), t, p5, p95)
else:
    wa, ha, a = load(sys.argv[2])
    wb, hb, b = load(sys.argv[3])
    assert (wa, ha) == (wb, hb)
    x0, y0, x1, y1 = (int(v) for v in sys.argv[4:8]) if len(sys.argv) > 4 else (0, HUD_ROWS, wa, ha)
    n = 0
    for y in range(max(y0, HUD_ROWS), y1):
        for x in range(x0, x1):
            p, q = a[y][x], b[y][x]
            if clay(p) and clay(q) and abs(luma(p) - luma(q)) > 25:
                n += 1
    print(n)
PY
pngpy() { PYTHONPATH=tests/sys "$py" "$tmp/png.py" "$@"; }
stats() { pngpy stats "$1"; }
diffpx() { pngpy diff "$@"; }
wirepx() { pngpy wire "$1"; }
legend() { pngpy legend "$1"; }

# 1. The default session in the window (as fast as it can), a screenshot every simulated second.
xvfb "$rel" sculpt --script scripts/default.scn --out "$tmp/live" --fast --width 480 \
    --height 360 --screenshot-every 1000 --screenshot "$tmp/last.png" --linger 0 \
    >"$tmp/live.txt" 2>&1 || { cat "$tmp/live.txt"; fail "live sculpt failed"; }
cat "$tmp/live.txt"
grep -q "live window .* frames" "$tmp/live.txt" || fail "no window ran (no 'live window' line)"
"$rel" sculpt --script scripts/default.scn --out "$tmp/head" --headless --quiet ||
    fail "headless sculpt failed"
env -u DISPLAY "$rel" sculpt --script scripts/default.scn --out "$tmp/nodisp" --quiet ||
    fail "sculpt without DISPLAY failed"
for f in final.ply telemetry.csv session.scn; do
    cmp -s "$tmp/live/$f" "$tmp/head/$f" || fail "$f differs between the window and --headless"
    cmp -s "$tmp/nodisp/$f" "$tmp/head/$f" || fail "$f differs without DISPLAY"
done
echo "window, --headless and no-DISPLAY runs wrote identical final.ply, telemetry.csv, session.scn"

n=$(ls "$tmp/live/frames" | wc -l)
echo "frames: $n"
[ "$n" -ge 5 ] || fail "only $n screenshots in $tmp/live/frames"
first=$(ls "$tmp/live/frames" | head -n 1)
early=$(ls "$tmp/live/frames" | awk -F'[_.]' '$2 >= 800 { print; exit }')
[ -n "$early" ] || fail "no frame after 0.8 s"
best_tool=0
for f in "$tmp/live/frames"/*.png "$tmp/last.png"; do
    set -- $(stats "$f")
    echo "$(basename "$f"): $1 x $2, clay share $3, tool pixels $4, clay luma p5 $5 p95 $6"
    [ "$1" = 480 ] && [ "$2" = 360 ] || fail "$f is $1 x $2, not 480 x 360"
    awk -v s="$3" 'BEGIN { exit !(s > 0.10 && s < 0.60) }' || fail "$f: clay share $3"
    [ $(($6 - $5)) -ge 40 ] || fail "$f: the clay is flat (luma $5..$6): not lit"
    [ "$4" -gt "$best_tool" ] && best_tool=$4
done
echo "most tool pixels in one frame: $best_tool"
[ "$best_tool" -ge 60 ] || fail "the tool is not visible in any frame ($best_tool pixels)"
changed=$(diffpx "$tmp/live/frames/$early" "$tmp/last.png")
echo "clay pixels changed between $early and the end: $changed"
[ "$changed" -ge 150 ] || fail "the sculpture did not change on screen ($changed pixels)"

# 2. Mouse sculpting with scripted input on a 640 x 480 window (real time): push a dent at the
#    centre, pull at another spot with Shift held, then the panel: beta, radius ×1.25³,
#    stiffness ×1.25, and Esc.
cat >"$tmp/input.txt" <<'EOF'
2.0 cursor 320 240
2.5 left down
4.5 left up
4.6 cursor 380 200
5.0 shift down
5.2 left down
6.5 left up
6.6 shift up
6.65 key B
6.7 key PLUS
6.75 key PLUS
6.8 key PLUS
6.85 key TAB
6.9 key PLUS
7.5 key ESC
EOF
xvfb "$rel" sculpt --mouse --input "$tmp/input.txt" --out "$tmp/mouse" --width 640 \
    --height 480 --screenshot-every 500 --linger 0 >"$tmp/mouse.txt" 2>&1 ||
    [ $? = 130 ] || { cat "$tmp/mouse.txt"; fail "mouse sculpt failed"; }
cat "$tmp/mouse.txt"
grep -q "radius 7.81 mm, stiffness 1.000 N/mm, beta spherical" "$tmp/mouse.txt" ||
    fail "the keyboard panel did not set radius 7.81 mm, stiffness 1.000, beta spherical"
set -- $(awk -F, 'NR > 1 && $11 == 1 { n[$10]++ } END { print n[1] + 0, n[2] + 0 }' \
    "$tmp/mouse/telemetry.csv")
echo "button held: $1 ticks with push, $2 ticks with pull (Shift)"
[ "$1" -ge 1000 ] || fail "the push stroke held the button only $1 ticks"
[ "$2" -ge 500 ] || fail "Shift did not turn the stroke into pull ($2 ticks)"
# The push dug: the clay flowed under it for a while, and it went in while it did (first to last
# flowing tick). Since 2026-12-04 the push no longer buzzes across the yield force in its bore,
# so the clay flows only while the hand drives the tool in (~260 ticks where the buzz made ~440).
set -- $(awk -F, 'NR > 1 && $13 == 1 { n[$10]++ }
    NR > 1 && $13 == 1 && $10 == 1 { if (!p) { x = $2; y = $3; z = $4 } p++; a = $2; b = $3; c = $4 }
    END { printf "%d %d %.2f\n", n[1] + 0, n[2] + 0, sqrt((a - x) ^ 2 + (b - y) ^ 2 + (c - z) ^ 2) }' \
    "$tmp/mouse/telemetry.csv")
echo "sculpting: $1 ticks pushing (the tool went $3 mm in meanwhile), $2 ticks pulling"
[ "$1" -ge 150 ] && [ "$2" -ge 100 ] && awk -v d="$3" 'BEGIN { exit !(d >= 2.0) }' ||
    fail "the mouse strokes did not sculpt ($1 / $2 ticks, the push $3 mm)"
before=$(ls "$tmp/mouse/frames" | awk -F'[_.]' '$2 >= 1900 { print; exit }')
after=$(ls "$tmp/mouse/frames" | awk -F'[_.]' '$2 >= 4500 { print; exit }')
[ -n "$before" ] && [ -n "$after" ] || fail "missing frames around the push stroke"
dent=$(diffpx "$tmp/mouse/frames/$before" "$tmp/mouse/frames/$after" 260 180 380 300)
echo "clay pixels changed under the cursor between $before and $after: $dent"
[ "$dent" -ge 100 ] || fail "no dent on screen where the mouse pushed ($dent pixels)"
# 3. The view's extras (real time, --mouse, Esc at 2.5 s): the second iso-surface as a wireframe
#    and the stiffness colour map with its legend, from the options and from the keys; the
#    solve step from the panel.
mouse_shot() { # NAME INPUT [OPTIONS...]
    name=$1 input=$2
    shift 2
    xvfb timeout 120 "$rel" sculpt --mouse --input "$input" --out "$tmp/$name" --width 480 \
        --height 360 --linger 0 --screenshot "$tmp/$name.png" "$@" >"$tmp/$name.txt" 2>&1 ||
        [ $? = 130 ] || { cat "$tmp/$name.txt"; fail "sculpt $name failed"; }
}
printf '2.5 key ESC\n' >"$tmp/esc.txt"
mouse_shot plain "$tmp/esc.txt"
mouse_shot extras "$tmp/esc.txt" --iso2 0.3 --colour stiffness
grep -q "view at the end     iso2 0.30, colour stiffness (1 .. 1 x default)" "$tmp/extras.txt" ||
    { cat "$tmp/extras.txt"; fail "--iso2 0.3 --colour stiffness did not reach the view"; }
w0=$(wirepx "$tmp/plain.png")
w1=$(wirepx "$tmp/extras.png")
echo "wire pixels: $w0 without the second iso-surface, $w1 with --iso2 0.3"
[ "$w0" -lt 30 ] || fail "wire-coloured pixels without --iso2 ($w0)"
[ "$w1" -ge 1500 ] || fail "the second iso-surface is not drawn ($w1 wire pixels)"
set -- $(stats "$tmp/plain.png")
c0=$3
set -- $(stats "$tmp/extras.png")
c1=$3
echo "clay-coloured share: $c0 plain, $c1 with the stiffness map"
awk -v a="$c0" -v b="$c1" 'BEGIN { exit !(a > 0.10 && b < 0.02) }' ||
    fail "the colour map did not recolour the clay ($c0 -> $c1)"
set -- $(legend "$tmp/extras.png")
echo "legend ends: ($1 $2 $3) .. ($4 $5 $6)"
[ "$3" -gt $(($1 + 80)) ] && [ "$4" -gt $(($6 + 80)) ] ||
    fail "no blue-to-red legend under the HUD"
set -- $(legend "$tmp/plain.png")
[ "$3" -lt $(($1 + 80)) ] || fail "a legend is drawn without a colour map"
# The same from the keys: I (on at 0.3), ] (0.4), M twice (mass), the panel's solve step + 1.
cat >"$tmp/keys.in" <<'EOF'
0.5 key I
0.6 key RBRACKET
0.7 key M
0.8 key M
0.9 key TAB
0.92 key TAB
0.94 key TAB
0.96 key TAB
0.98 key TAB
1.0 key TAB
1.02 key TAB
1.04 key TAB
1.1 key PLUS
2.5 key ESC
EOF
mouse_shot keys "$tmp/keys.in"
grep "view at the end" "$tmp/keys.txt"
grep -q "view at the end     iso2 0.40, colour mass (1 .. 1 x default), solve step 12.5 ms" \
    "$tmp/keys.txt" || fail "the keys did not set iso2 0.40, colour mass, solve step 12.5 ms"
w2=$(wirepx "$tmp/keys.png")
echo "wire pixels after the keys: $w2"
[ "$w2" -ge 1500 ] || fail "key I did not show the second iso-surface ($w2 wire pixels)"
set +e
"$rel" sculpt --headless --iso2 0.3 --out "$tmp/bad" 2>"$tmp/err"
st=$?
"$rel" sculpt --iso2 2 --out "$tmp/bad" 2>>"$tmp/err"
st2=$?
"$rel" sculpt --colour hue --out "$tmp/bad" 2>>"$tmp/err"
st3=$?
set -e
cat "$tmp/err"
[ "$st" = 2 ] && [ "$st2" = 2 ] && [ "$st3" = 2 ] || fail "bad view options: $st $st2 $st3"
grep -q "iso2 needs the window" "$tmp/err" && grep -q "level 0.05..0.95" "$tmp/err" &&
    grep -q "stiffness, mass or none" "$tmp/err" || fail "view option error text"

# 4. Errors: one line each, nothing run.
printf '0.5 key 1\n0.2 key F\n' >"$tmp/bad.txt"
if xvfb "$rel" sculpt --input "$tmp/bad.txt" --out "$tmp/bad" 2>"$tmp/err"; then
    fail "a bad input file was accepted"
fi
cat "$tmp/err"
grep -q "bad.txt: line 2: time goes backwards: '0.2'" "$tmp/err" || fail "input error text"
[ "$(wc -l <"$tmp/err")" = 1 ] || fail "the input error is not one line"
[ ! -e "$tmp/bad/final.ply" ] || fail "a session ran despite a bad input file"
set +e
env -u DISPLAY "$rel" sculpt --mouse --out "$tmp/bad" 2>"$tmp/err"
st=$?
set -e
[ "$st" = 2 ] && grep -q "needs the window" "$tmp/err" || fail "--mouse without a display: $st"
echo "sculpt window: all checks passed"
