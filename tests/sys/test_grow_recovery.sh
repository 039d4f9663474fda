#!/bin/sh
# Crash safety when the clay grows past the grid's old box (sparse grid): an `action add`
# stroke drags clay from the sphere out past x = 54.4 mm (the old 88^3 box's edge); the journal
# rebases onto checkpoints whose box holds the grown grid (docs/model.md "The session's grid").
# The session is killed with SIGKILL after such a rebase; `argil recover` must give, byte for
# byte, the model a rerun dumps at the same journal record, and that model reaches past the edge.
set -eu
bin="$REL/argil"
tmp=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

script="$tmp/grow.scn"
printf '%s\n' "set radius_mm 4" "tool touch" "move 45 0 45 0.5" "move 45 0 0 0.5" \
    "move 36 0 0 0.3" "tool carve" "action add" "press 1" "move 28 0 0 0.2" "move 72 0 0 2.0" \
    "release 1" "move 80 0 0 0.3" >"$script"

# 1. Run until the journal has rebased at least once (base 2) and holds records, then kill -9.
# The rebase writes journal-base-2 first and then the journal.log that replaces the old one; the
# poll waits for that one (newer than the base: the old log is large, and a size test alone
# fired between the two writes, which a loaded machine stretches: 5 kills of 5 there). A rebased
# journal holds no record at first (its base already has the step that grew the clay); a kill
# then, or one the poll could not tell apart, is retried, since it is not the state this test
# is about.
attempt=0
while :; do
    attempt=$((attempt + 1))
    [ "$attempt" -le 5 ] || fail "5 sessions could not be killed after a rebase with records"
    rm -rf "$tmp/s"
    "$bin" sculpt --device sim --script "$script" --out "$tmp/s" --quiet --autosave-s 0.05 &
    pid=$!
    polls=0
    while :; do
        size=$(stat -c %s "$tmp/s/journal.log" 2>/dev/null || echo 0)
        [ -e "$tmp/s/journal-base-2.argil" ] && [ "$tmp/s/journal.log" -nt "$tmp/s/journal-base-2.argil" ] &&
            [ "$size" -gt 20000 ] && break
        kill -0 "$pid" 2>/dev/null || break
        polls=$((polls + 1))
        [ "$polls" -lt 6000 ] || fail "no rebased journal after 60 s"
        sleep 0.01
    done
    status=0
    kill -9 "$pid" 2>/dev/null || true
    wait "$pid" || status=$?
    pid=
    if [ "$status" != 137 ] || [ ! -s "$tmp/s/journal.log" ] || [ -e "$tmp/s/final.ply" ]; then
        echo "attempt $attempt: the session ended before the kill; again"
        continue
    fi
    # 2. Recover (from a rebased base, with records of its own).
    rm -f "$tmp/rec.argil"
    "$bin" recover "$tmp/s" -o "$tmp/rec.argil" >"$tmp/rec.txt" || { cat "$tmp/rec.txt"; fail "recover failed"; }
    if ! grep -Eq "base snapshot .*journal-base-([2-9]|[1-9][0-9]+)\.argil" "$tmp/rec.txt"; then
        echo "attempt $attempt: killed before the rebased journal replaced the old one; again"
        continue
    fi
    records=$(sed -n 's/.*journal records *\([0-9]*\) (numbers.*/\1/p' "$tmp/rec.txt")
    [ -n "$records" ] || { cat "$tmp/rec.txt"; fail "cannot read the number of journal records"; }
    [ "$records" -gt 0 ] && break
    echo "attempt $attempt: killed before the rebased journal's first record; again"
done
cat "$tmp/rec.txt"

# Rebuild the same record in a deterministic rerun.
last=$(sed -n 's/.*journal records *[0-9]* (numbers [0-9]*\.\.\([0-9]*\)).*/\1/p' "$tmp/rec.txt")
[ -n "$last" ] || fail "cannot read the last record number"
"$bin" sculpt --device sim --script "$script" --out "$tmp/ref" --quiet --autosave-s 0.05 \
    --debug-journal-dump "$last" "$tmp/ref.argil" >/dev/null
cmp "$tmp/rec.argil" "$tmp/ref.argil" || fail "the recovered model is not the model at record $last"

# 3. The recovered model's box is wider than the old 88 samples and its mesh reaches past the edge.
"$bin" info "$tmp/rec.argil" >"$tmp/info.txt"
nx=$(sed -n 's/^ *grid *\([0-9]*\) x .*/\1/p' "$tmp/info.txt")
[ -n "$nx" ] && [ "$nx" -gt 88 ] || { cat "$tmp/info.txt"; fail "the recovered grid is $nx samples wide, not more than 88"; }
"$bin" mesh "$tmp/rec.argil" -o "$tmp/rec.obj" --quiet || fail "the recovered model does not mesh"
maxx=$(awk '$1 == "v" { if ($2 > m) m = $2 } END { printf "%.1f", m * 1000 }' "$tmp/rec.obj")
echo "recovered: grid $nx samples wide, mesh reaches x = $maxx mm (old edge 54.4 mm)"
awk -v m="$maxx" 'BEGIN { exit !(m > 60.0) }' || fail "the recovered mesh reaches only x = $maxx mm"
echo "PASS: grown clay recovered bit for bit after a rebase (record $last)"
