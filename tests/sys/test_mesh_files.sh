#!/bin/sh
# argil fit / mesh / info end to end: a sphere point cloud is fitted (RBF, octree B-spline, without
# normals, and as a closed STL through its signed distance), meshed to every export format, each
# file loads in assimp and is watertight, every surface is within 0.5 % (mean) and 2 % (max) of
# the true sphere, an octree model re-meshed finer comes from its B-splines (and argil info lists
# the octree), and bad files, clouds that bound no solid and bad options give one clear line.
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
# clouds that bound no solid: one clear line each, nothing written
awk 'BEGIN { for (i = 0; i < 500; i++) print 0.01 * (i % 3), 0.02, 0 }' >"$tmp/dup.xyz"
expect_error 1 "dup.xyz: fewer than 4 distinct points" fit "$tmp/dup.xyz" -o "$tmp/y.argil"
awk 'BEGIN { srand(3); for (i = 0; i < 2000; i++) print 0.05 * rand(), 0.05 * rand(), 0 }' >"$tmp/flat.xyz"
expect_error 1 "flat.xyz: the points lie on one plane or line" fit "$tmp/flat.xyz" -o "$tmp/y.argil"
expect_error 1 "flat.xyz: the points lie on one plane or line" fit "$tmp/flat.xyz" -o "$tmp/y.argil" --method rbf
[ ! -e "$tmp/y.argil" ] || fail "a refused cloud still wrote a model"
# sphere surface check on an ASCII PLY mesh of a model: mean <= 0.5 %, max <= 2 % of 60 mm
check_sphere() { # model label
    "$bin" mesh "$1" -o "$tmp/c.ply" --ascii --resolution 60 --quiet || fail "$2: mesh"
    awk -v label="$2" 'NR == 1, /end_header/ { next } NF == 6 { r = sqrt($1 * $1 + $2 * $2 + $3 * $3); d = r - 0.03;
         if (d < 0) d = -d; s += d; n++; if (d > m) m = d }
         END { printf "%s: %d vertices, mean %.4f %%, max %.4f %% of size\n", label, n, 100 * s / n / 0.06, 100 * m / 0.06;
               exit !(n > 1000 && s / n <= 0.005 * 0.06 && m <= 0.02 * 0.06) }' "$tmp/c.ply" || fail "$2: sphere surface off"
}
# the octree B-spline fit (Hua & Qin 4), with a depth limit; the model file keeps its OCTB section
"$bin" fit "$tmp/s.xyz" -o "$tmp/o.argil" --method octree --max-depth 3 --resolution 48 --quiet \
    || fail "octree fit failed"
grep -q OCTB "$tmp/o.argil" || fail "the octree form is not in the model file"
"$bin" info "$tmp/o.argil" >"$tmp/i" || fail "info on the octree model failed"
grep -q "octree .* 1 nodes, 1 leaves, depth 0, .* fit error rms" "$tmp/i" || { cat "$tmp/i"; fail "info does not show the octree form"; }
check_sphere "$tmp/o.argil" "octree fit"
# a split octree on a coarse 32-sample grid: argil info lists the section, and mesh --resolution
# evaluates the B-splines, so a finer mesh has more triangles and sits closer to the sphere than
# the stored grid could give (trilinear resampling of it: mean ~0.06 % of size at 80 samples)
"$bin" fit "$tmp/s.xyz" -o "$tmp/d.argil" --method octree --max-depth 2 --tolerance 0.00002 \
    --resolution 32 --quiet || fail "split octree fit failed"
"$bin" info "$tmp/d.argil" >"$tmp/i" || fail "info on the split octree model failed"
grep -q "octree .* 9 nodes, 8 leaves, depth 1, cube .* mm (6988 bytes), fit error rms .* mm, max .* mm" "$tmp/i" \
    || { cat "$tmp/i"; fail "info does not show the split octree form"; }
for r in 30 80; do
    "$bin" mesh "$tmp/d.argil" -o "$tmp/d$r.ply" --ascii --resolution $r --quiet || fail "octree mesh at $r"
    assimp info "$tmp/d$r.ply" >"$tmp/a$r" 2>&1 || { cat "$tmp/a$r"; fail "assimp cannot load the octree mesh at $r"; }
done
f30=$(sed -n 's/^Faces: *\([0-9]*\).*/\1/p' "$tmp/a30"); f80=$(sed -n 's/^Faces: *\([0-9]*\).*/\1/p' "$tmp/a80")
[ -n "$f30" ] && [ -n "$f80" ] && [ "$f30" -gt 0 ] && [ "$f80" -gt "$f30" ] \
    || fail "octree mesh at 80 has $f80 faces, at 30 $f30 (want more at 80)"
awk 'NR == 1, /end_header/ { next } NF == 6 { r = sqrt($1 * $1 + $2 * $2 + $3 * $3); d = r - 0.03;
     if (d < 0) d = -d; s += d; n++; if (d > m) m = d }
     END { printf "octree resampled at 80: %d vertices, mean %.4f %%, max %.4f %% of size\n", n, 100 * s / n / 0.06, 100 * m / 0.06;
           exit !(n > 10000 && s / n <= 0.0002 * 0.06 && m <= 0.001 * 0.06) }' "$tmp/d80.ply" \
    || fail "octree mesh at 80 not evaluated from the B-splines (surface off)"
# a cloud without normals: PCA + MST orientation, then the fit (auto picks octree above 1000 points)
awk 'BEGIN { n = 1500; for (i = 0; i < n; i++) { z = 1 - 2 * (i + 0.5) / n; r = sqrt(1 - z * z);
     t = i * 3.14159265 * (3 - sqrt(5)); printf "%.7f %.7f %.7f\n", 0.03 * r * cos(t), 0.03 * r * sin(t), 0.03 * z } }' >"$tmp/p.xyz"
"$bin" fit "$tmp/p.xyz" -o "$tmp/p.argil" --resolution 48 >"$tmp/o" 2>/dev/null || fail "fit without normals failed"
grep -q "octree B-spline" "$tmp/o" || { cat "$tmp/o"; fail "auto did not choose the octree for 1500 points"; }
check_sphere "$tmp/p.argil" "unoriented cloud"
# a closed mesh becomes a signed distance grid; an open one is refused with the count
"$bin" mesh "$tmp/s.argil" -o "$tmp/m.stl" --resolution 40 --quiet || fail "mesh for sdf"
"$bin" fit "$tmp/m.stl" -o "$tmp/m.argil" --resolution 48 --quiet || fail "fit of a closed STL failed"
check_sphere "$tmp/m.argil" "closed mesh -> sdf"
cnt=$(od -An -tu4 -j80 -N4 "$tmp/m.stl" | tr -d ' ')
{ head -c 80 "$tmp/m.stl"; printf "$(printf '\\%03o\\%03o\\%03o\\%03o' $(((cnt - 1) & 255)) $(((cnt - 1) >> 8 & 255)) $(((cnt - 1) >> 16 & 255)) $(((cnt - 1) >> 24 & 255)))";
  tail -c +85 "$tmp/m.stl" | head -c $(((cnt - 1) * 50)); } >"$tmp/open.stl"
expect_error 1 "open.stl: the mesh is not closed (3 boundary" fit "$tmp/open.stl" -o "$tmp/y.argil"
expect_error 2 "--max-depth needs a number from 0 to 10" fit "$tmp/s.xyz" -o "$tmp/y.argil" --max-depth 11
expect_error 2 "--method needs auto, octree, rbf, sdf or grid" fit "$tmp/s.xyz" -o "$tmp/y.argil" --method spline
expect_error 2 "must end in .ply, .stl or .obj" mesh "$tmp/s.argil" -o "$tmp/x.vtk"
expect_error 2 "--resolution needs a number" mesh "$tmp/s.argil" -o "$tmp/x.ply" --resolution 1
expect_error 2 "unknown option '--bogus'" fit "$tmp/s.xyz" --bogus
expect_error 1 "unknown extension" info "$tmp/thing.foo"
echo "mesh files: all checks passed"
