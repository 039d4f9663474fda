#!/bin/sh
# Painted colour end to end (`action paint`): the live window under Xvfb shows a red
# stroke where the script paints (and no red before it), the window and a headless run write the
# same model.argil, `argil info` reports the painted colour and `argil mesh` exports it as vertex
# colours; the session's own final.ply carries the colour too (byte for byte `argil mesh`'s export
# of its model.argil: red vertices only along the stroke, every other vertex the clay's grey),
# while an unpainted session's final.ply has no colour properties; then a painting session killed
# with SIGKILL mid-stroke is recovered by `argil recover` byte for byte as the model at its last
# journal record (colour records after a checkpoint whose base already holds colour), and the
# recovered .ply holds that colour (byte for byte `argil mesh` of the recovered model); last,
# `argil connect` keeps a paint tool's settings in its model.argil (TOOL colour, PNTS rate).
# The GL run uses the release build, as tests/sys/test_sculpt_window.sh.
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

# "ply colours": a binary PLY's vertices (27-byte records with red green blue), counted against
# a stroke's path (default: the script's (-9,0,27.6) -> (0,0,27.4) -> (9,0,27.6) mm) and paint
# colour (default 230 20 20): vertices, paint-coloured ones, 204 204 204 ones, within 3 mm of the
# path, of those paint-coloured, the farthest paint-coloured one (mm); or "nocolour N" for a file
# without colour properties. Arguments: FILE [R G B X0 Y0 Z0 X1 Y1 Z1 X2 Y2 Z2].
cat >"$tmp/plyc.py" <<'PY'
import math, struct, sys
b = open(sys.argv[1], 'rb').read()
end = b.index(b'end_header\n') + 11
head = b[:end].decode().split('\n')
nv = int([l for l in head if l.startswith('element vertex')][0].split()[2])
if 'property uchar red' not in head:
    print('nocolour', nv)
    sys.exit(0)
path = [(-9.0, 0.0, 27.6), (0.0, 0.0, 27.4), (9.0, 0.0, 27.6)]
paint = (230, 20, 20)
if len(sys.argv) == 14:
    paint = tuple(int(v) for v in sys.argv[2:5])
    a = [float(v) for v in sys.argv[5:]]
    path = [tuple(a[0:3]), tuple(a[3:6]), tuple(a[6:9])]
def seg(p, a, c):
    ab = [c[i] - a[i] for i in range(3)]
    ap = [p[i] - a[i] for i in range(3)]
    t = max(0.0, min(1.0, sum(ab[i] * ap[i] for i in range(3)) / sum(v * v for v in ab)))
    return math.sqrt(sum((ap[i] - t * ab[i]) ** 2 for i in range(3)))
red = grey = near = near_red = 0
far = 0.0
for i in range(nv):
    o = end + 27 * i
    p = [v * 1e3 for v in struct.unpack_from('<3f', b, o)]
    c = tuple(b[o + 24:o + 27])
    d = min(seg(p, path[0], path[1]), seg(p, path[1], path[2]))
    red += c == paint
    grey += c == (204, 204, 204)
    far = max(far, d) if c == paint else far
    near += d < 3.0
    near_red += d < 3.0 and c == paint
print(nv, red, grey, near, near_red, '%.1f' % far)
PY
plyc() { "$py" "$tmp/plyc.py" "$@"; }

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
# the session's final.ply: the same colours, the same bytes
cmp "$tmp/head/final.ply" "$tmp/painted.ply" ||
    fail "final.ply differs from argil mesh's export of the session's model.argil"
set -- $(plyc "$tmp/head/final.ply")
echo "final.ply: $1 vertices, $2 red 230 20 20 (farthest $6 mm from the path), $3 grey 204;" \
    "$4 within 3 mm of the path, $5 of them red"
[ "$1" != nocolour ] || fail "final.ply of a painted session has no vertex colours"
# measured: 10824 vertices, 148 red (farthest 4.5 mm: the 4 mm ball + a sample), 10676 grey,
# 88 of 88 within 3 mm red
[ "$2" -ge 100 ] || fail "only $2 red vertices in final.ply"
[ $(($2 + $3)) = "$1" ] || fail "final.ply holds colours other than the paint and the grey"
[ "$4" -ge 40 ] && [ $(($5 * 100)) -ge $(($4 * 95)) ] ||
    fail "$5 of the $4 vertices within 3 mm of the stroke are red"
awk -v f="$6" 'BEGIN { exit !(f <= 7.0) }' || fail "a red vertex $6 mm from the stroke"
# an unpainted session's model has no colour section (the file as before)
"$rel" sculpt --script scripts/default.scn --out "$tmp/plain" --headless --quiet ||
    fail "default sculpt failed"
"$rel" info "$tmp/plain/model.argil" | grep -q "colours none" || fail "an unpainted model has colour"
set -- $(plyc "$tmp/plain/final.ply")
[ "$1" = nocolour ] || fail "an unpainted session's final.ply has vertex colours"

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
# the recovered mesh carries that colour: argil mesh's export of the recovered model, byte for
# byte, and painted vertices (red, blue or green) along the strokes
"$rel" mesh "$tmp/rec.argil" -o "$tmp/rec-mesh.ply" >/dev/null || fail "argil mesh of the recovered model"
cmp "$tmp/rec.ply" "$tmp/rec-mesh.ply" || fail "recover's .ply differs from argil mesh's export"
set -- $(plyc "$tmp/rec.ply")
[ "$1" != nocolour ] || fail "recover's .ply has no vertex colours"
echo "recovered .ply: $1 vertices, $(($1 - $3)) painted (not grey), $2 of them 230 20 20"
[ $(($1 - $3)) -ge 100 ] || fail "only $(($1 - $3)) painted vertices in recover's .ply"
echo "recovered model = model at journal record $last, byte for byte, with $replayed colour" \
    "samples replayed after the checkpoint ($(stat -c %s "$tmp/rec.argil") bytes)"

# 4. argil connect keeps a paint tool's settings: TOOL's paint rgb and the PNTS soft-paint rate
#    (the sim board's hand holds still above the clay with no button, so nothing is painted: no
#    COLR and no vertex colours, final.ply as a plain connect on the same B-spline model writes).
cat >"$tmp/sections.py" <<'PY'
import struct, sys
b = open(sys.argv[1], 'rb').read()
pos, out = 32, {}
for _ in range(struct.unpack_from('<I', b, 12)[0]):
    tag = b[pos:pos + 4].decode()
    n = struct.unpack_from('<Q', b, pos + 4)[0]
    out[tag] = b[pos + 12:pos + 12 + n]
    pos += 16 + n
tool = out['TOOL']
print(' '.join(sorted(out)), 'rgb %d %d %d' % tuple(tool[12:15]),
      'rate %g' % struct.unpack('<f', out['PNTS'])[0] if 'PNTS' in out else 'rate none')
PY
"$rel" connect --device sim --seconds 1 --quiet --action soft-paint --strength 30 \
    --out "$tmp/cp" || fail "connect --action soft-paint failed"
set -- $("$py" "$tmp/sections.py" "$tmp/cp/model.argil")
echo "connect --action soft-paint --strength 30: sections $1 $2 $3 $4 $5, paint $6 $7 $8 $9, ${10} ${11}"
[ "$1 $2 $3 $4 $5" = "GRID MATL PNTS STAT TOOL" ] || fail "connect's model.argil sections: $*"
[ "$7 $8 $9" = "200 60 40" ] || fail "connect's paint colour is $7 $8 $9, want the default 200 60 40"
[ "${11}" = 30 ] || fail "connect's soft-paint rate is ${11}, want 30"
set -- $(plyc "$tmp/cp/final.ply")
[ "$1" = nocolour ] || fail "connect's final.ply has colours though nothing was painted"
"$rel" connect --device sim --seconds 1 --quiet --global-solve bspline --out "$tmp/cq" ||
    fail "plain connect failed"
set -- $("$py" "$tmp/sections.py" "$tmp/cq/model.argil")
[ "$1 $2 $3 $4 $5" = "GRID MATL STAT TOOL rgb" ] || fail "a plain connect's model.argil: $*"
cmp "$tmp/cp/final.ply" "$tmp/cq/final.ply" || fail "the paint settings changed connect's final.ply"

# 5. argil connect paints: a scripted board on UDP (tests/sys/fake_paint_board.py: HELLO, then
#    1 kHz telemetry ACTIVE, board tool carve, button 1 held, the stylus drawn 18 mm along y 2 mm
#    inside the +x side of connect's clay) with --action paint: model.argil holds COLR (the default
#    colour 200 60 40 on the samples along the stroke: measured 596) and the paint settings, and
#    final.ply is argil mesh's export of that model byte for byte, vertex colours included. (How
#    many vertices show the paint is printed, not asserted: with this board, which sends no
#    impulses, connect's B-spline solve wears the clay away around the held stylus, the eraser's
#    volume to the last bit, so the painted samples end up outside the surface.)
org=$("$rel" info "$tmp/cq/model.argil" | sed -n 's/.*origin (\([-0-9.]*\), \([-0-9.]*\), \([-0-9.]*\)) mm.*/\1 \2 \3/p')
[ -n "$org" ] || fail "cannot read connect's grid origin"
# the clay's centre: the grid's centre (72 samples of 1.25 mm: 44.375 mm in) 40 mm lower
set -- $(echo "$org" | awk '{ printf "%.3f %.3f %.3f", $1 + 44.375, $2 + 44.375, $3 + 4.375 }')
cx=$1; cy=$2; cz=$3
port=$((21000 + $$ % 20000))
"$py" tests/sys/fake_paint_board.py "$port" "$cx" "$cy" "$cz" 4 >"$tmp/fb.out" 2>&1 &
pid=$!
sleep 0.3
st=0
"$rel" connect --device "udp:127.0.0.1:$port" --seconds 3 --quiet --action paint \
    --out "$tmp/cf" >"$tmp/cf.out" 2>"$tmp/cf.err" || st=$?
wait "$pid" || fail "the scripted board failed: $(cat "$tmp/fb.out")"
pid=
[ "$st" = 0 ] || fail "connect to the scripted board: exit $st: $(tail -n 3 "$tmp/cf.err")"
set -- $("$py" "$tmp/sections.py" "$tmp/cf/model.argil")
[ "$1 $2 $3 $4 $5 $6" = "COLR GRID MATL PNTS STAT TOOL" ] || fail "connect's painted model.argil: $*"
[ "$8 $9 ${10}" = "200 60 40" ] && [ "${12}" = 20 ] || fail "connect's paint settings: $*"
n=$("$rel" info "$tmp/cf/model.argil" |
    sed -n 's/.*colour    painted on \([0-9]*\) samples (200 60 40 on \([0-9]*\) of them).*/\1 \2/p')
[ -n "$n" ] || fail "argil info: connect's model holds no 200 60 40 paint"
set -- $n
echo "connect + scripted board: $1 samples painted, $2 of them 200 60 40"
# a 4 mm ball 2 mm deep along up to 18 mm (measured: 316 to 800 samples)
[ "$1" -ge 100 ] && [ "$2" = "$1" ] || fail "connect painted $1 samples"
"$rel" mesh "$tmp/cf/model.argil" -o "$tmp/cf-mesh.ply" >/dev/null || fail "argil mesh of connect's model"
cmp "$tmp/cf/final.ply" "$tmp/cf-mesh.ply" || fail "connect's final.ply differs from argil mesh's export"
set -- $(plyc "$tmp/cf/final.ply" 200 60 40 $(awk -v x="$cx" -v y="$cy" -v z="$cz" \
    'BEGIN { printf "%.3f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %.3f", x + 28, y - 9, z, x + 28, y, z, x + 28, y + 9, z }'))
echo "connect final.ply: $1 vertices, $2 painted 200 60 40 (farthest $6 mm from the stroke), $3 grey"
[ "$1" != nocolour ] || fail "connect's final.ply has no vertex colours"
[ $(($2 + $3)) = "$1" ] || fail "connect's final.ply: colours other than 200 60 40 and the grey"
awk -v f="$6" 'BEGIN { exit !(f <= 7.0) }' || fail "a painted vertex $6 mm from the stroke"
echo "painted colour: in final.ply, the recovered .ply and model.argil, from argil sculpt and argil connect"
