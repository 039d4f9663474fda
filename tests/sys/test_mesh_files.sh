#!/bin/sh
# argil fit / mesh / info end to end: a sphere point cloud is fitted, meshed to every export
# format, each file loads in assimp and is watertight, the surface is within 0.5 % (mean) and
# 2 % (max) of the true sphere, and bad files and options give one clear line.
set -eu
bin="$SAN/argil"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# 800 points on a 30 mm sphere (Fibonacci spiral) with outward normals
awk 'BEGIN { n = 800; for (i = 0; i < n; i++) { z = 1 - 2 * (i + 0.5) / n; r = sqrt(1 - z * z);
     t = i * 3.14159265 * (3 - sqrt(5)); x = r * cos(t); y = r * sin(t);
     printf "%.7f %.7f %.7f %.6f %.6f %.6f\n", 0.03 * x, 0.03 * y, 0.03 * z, x, y, z } }' >"$tmp/s.xyz"
"$bin" fit "$tmp/s.xyz" -o "$tmp/s.argil" --samples 150 --resolution 40 --quiet || fail "fit failed"
"$bin" info "$tmp/s.argil" >"$tmp/i" || fail "info on the model failed"
grep -q "rbf .* centres" "$tmp/i" || fail "info does not show the RBF form"

for f in s.ply s.stl s.obj; do
    "$bin" mesh "$tmp/s.argil" -o "$tmp/$f" --quiet || fail "mesh -o $f failed"
    assimp info "$tmp/$f" >"$tmp/a" 2>&1 || { cat "$tmp/a"; fail "assimp cannot load $f"; }
    grep -q "Faces: *[1-9]" "$tmp/a" || fail "assimp sees no faces in $f"
    "$bin" info "$tmp/$f" >"$tmp/i" || fail "argil info $f failed"
    grep -q "watertight (0 boundary, 0 non-manifold" "$tmp/i" || { cat "$tmp/i"; fail "$f not watertight"; }
done
"$bin" mesh "$tmp/s.argil" -o "$tmp/a.ply" --ascii --resolution 60 --quiet || fail "ascii ply"
assimp info "$tmp/a.ply" >/dev/null 2>&1 || fail "assimp cannot load the ASCII PLY"
# distance of every vertex to the true sphere (size = 60 mm): mean <= 0.5 %, max <= 2 %
awk 'NR == 1, /end_header/ { next } NF == 6 { r = sqrt($1 * $1 + $2 * $2 + $3 * $3); d = r - 0.03;
     if (d < 0) d = -d; s += d; n++; if (d > m) m = d }
     END { printf "%d vertices, mean %.4f %%, max %.4f %% of size\n", n, 100 * s / n / 0.06, 100 * m / 0.06;
           exit !(n > 1000 && s / n <= 0.005 * 0.06 && m <= 0.02 * 0.06) }' "$tmp/a.ply" \
    || fail "sphere surface off"
# a region at another iso is still closed
"$bin" mesh "$tmp/s.argil" -o "$tmp/r.ply" --iso 0.3 --region -0.05 -0.05 -0.05 0 0.05 0.05 --quiet \
    || fail "region mesh"
"$bin" info "$tmp/r.ply" | grep -q "watertight" || fail "region mesh not closed"

expect_error() { # status text args...
    want=$1; text=$2; shift 2
    set +e
    "$bin" "$@" >"$tmp/o" 2>"$tmp/e"
    st=$?
    set -e
    [ "$st" = "$want" ] || { cat "$tmp/e"; fail "'$*' exited $st, want $want"; }
    grep -q -- "$text" "$tmp/e" || { cat "$tmp/e"; fail "'$*' did not say '$text'"; }
    [ "$(wc -l <"$tmp/e")" -le 1 ] || { cat "$tmp/e"; fail "'$*' printed more than one line"; }
}
cp "$tmp/s.argil" "$tmp/bad.argil"
printf 'X' | dd of="$tmp/bad.argil" bs=1 seek=100 conv=notrunc 2>/dev/null
expect_error 1 "bad.argil: byte .*checksum mismatch" info "$tmp/bad.argil"
expect_error 1 "bad.argil: byte .*checksum mismatch" mesh "$tmp/bad.argil" -o "$tmp/x.ply"
[ ! -e "$tmp/x.ply" ] || fail "a refused model still wrote a mesh"
printf '0 0 0\n1 2\n' >"$tmp/bad.xyz"
expect_error 1 "bad.xyz: line 2: 2 values" fit "$tmp/bad.xyz" -o "$tmp/y.argil"
awk '{ print $1, $2, $3 }' "$tmp/s.xyz" >"$tmp/p.xyz"
expect_error 1 "p.xyz: no normals" fit "$tmp/p.xyz" -o "$tmp/y.argil"
expect_error 2 "not in this build" fit "$tmp/s.xyz" -o "$tmp/y.argil" --max-depth 6
expect_error 2 "must end in .ply, .stl or .obj" mesh "$tmp/s.argil" -o "$tmp/x.vtk"
expect_error 2 "--resolution needs a number" mesh "$tmp/s.argil" -o "$tmp/x.ply" --resolution 1
expect_error 2 "unknown option '--bogus'" fit "$tmp/s.xyz" --bogus
expect_error 1 "unknown extension" info "$tmp/thing.foo"
echo "mesh files: all checks passed"
