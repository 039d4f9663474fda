#!/bin/sh
# make run's session with the release build: the summary a person reads, files a third-party
# mesh tool loads, and byte-identical output for the same script.
set -eu
bin="$REL/argil"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$bin" sculpt --device sim --script scripts/default.scn --out "$tmp/a" >"$tmp/summary"
cat "$tmp/summary"
"$bin" sculpt --device sim --script scripts/default.scn --out "$tmp/b" --quiet
for f in final.ply telemetry.csv session.scn; do
    [ -s "$tmp/a/$f" ] || fail "$f missing or empty"
    cmp -s "$tmp/a/$f" "$tmp/b/$f" || fail "$f differs between two runs of the same script"
done
ls "$tmp/a" | grep -q '\.tmp$' && fail "a temporary file was left behind"

# Tick compute is thread CPU time; on a shared VM a descheduled vCPU is sometimes charged to the
# ticking thread (one 2.4 ms "tick" seen in CI with nothing else in it). Speed is make bench's job
# (bench_ticks, callgrind); what a person would notice is the board's answer to overruns: it must
# end ACTIVE, never have faulted on a streak (3 in a row), and the files above are byte-identical.
grep -q 'board state *ACTIVE' "$tmp/summary" || fail "the board did not end ACTIVE"
streak=$(sed -n 's/.*overruns (worst streak \([0-9]*\)).*/\1/p' "$tmp/summary")
[ -n "$streak" ] || fail "the summary has no overrun streak"
[ "$streak" -lt 3 ] || fail "a streak of $streak deadline overruns (3 fault the board)"
grep -q 'watertight' "$tmp/summary" || fail "the summary does not report a watertight mesh"
grep -q 'NOT watertight' "$tmp/summary" && fail "the mesh is not watertight"
# Peak force within the limit, read from the summary.
awk '/peak force/ { if ($3 + 0 > $6 + 0 + 1e-6) exit 1 }' FS='[ ()]+' "$tmp/summary" ||
    fail "peak force above the limit"

# The telemetry CSV: header, one row per tick, forces bounded.
head -n 1 "$tmp/a/telemetry.csv" | grep -q '^time_s,x_mm,y_mm,z_mm,fx_n,fy_n,fz_n,force_n,state' ||
    fail "telemetry.csv header"
awk -F, 'NR > 1 && $8 > 3.3 + 1e-6 { bad = 1 } END { exit bad }' "$tmp/a/telemetry.csv" ||
    fail "a telemetry row shows force above 3.3 N"

# A third-party reader loads the mesh.
if command -v assimp >/dev/null 2>&1; then
    assimp info "$tmp/a/final.ply" >"$tmp/assimp" 2>&1 || { cat "$tmp/assimp"; fail "assimp cannot load final.ply"; }
    grep -Eq 'Faces: +[1-9]' "$tmp/assimp" || { cat "$tmp/assimp"; fail "assimp sees no faces"; }
    echo "assimp: $(grep -E 'Vertices|Faces' "$tmp/assimp" | tr -s ' ' | tr '\n' ' ')"
else
    fail "assimp (assimp-utils) is not installed: run toolchain/install-deps.sh"
fi
echo "default session files: all checks passed"
