#!/bin/sh
# Crash safety: a scripted session killed with SIGKILL in the middle, then `argil recover`. The
# recovered model must be byte for byte the model at the last journal record (a deterministic
# rerun of the same script dumps the model at that record), the work lost must be within the
# autosave interval, and the next start must offer the recovery instead of overwriting it. The
# script paints the clay (stiffness 4x, mass 0.5x) before the kill: the painted material is part
# of the model, so it is recovered as of the last record too.
set -eu
bin="$REL/argil"
tmp=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
autosave_s=0.5
now_ms() { date +%s%3N; }
# expect STATUS TEXT ARGS...: argil exits with STATUS and says TEXT on stderr.
expect() {
    want=$1 text=$2
    shift 2
    st=0
    "$bin" "$@" >/dev/null 2>"$tmp/err" || st=$?
    [ "$st" = "$want" ] || fail "argil $*: exit $st, wanted $want"
    grep -qF -- "$text" "$tmp/err" || { cat "$tmp/err"; fail "argil $*: no '$text'"; }
}

# 0. Usage errors are one clear line.
mkdir "$tmp/empty"
expect 2 "usage: argil recover" recover
expect 2 "unknown option '--bogus'" recover --bogus
expect 1 "holds no journal" recover "$tmp/empty"
expect 2 "--autosave-s needs seconds" sculpt --autosave-s 0
expect 2 "--checkpoint-s needs seconds" sculpt --checkpoint-s x
"$bin" --help | grep -q "recover" || fail "argil --help does not list 'recover'"

# The default session with two paints where the stylus first touches the clay (~1 s in).
script="$tmp/paint.scn"
sed 's/^move 0 0 32 0.4$/&\npaint stiffness 4 radius 10\npaint mass 0.5 radius 8/' \
    scripts/default.scn >"$script"
[ "$(grep -c '^paint ' "$script")" = 2 ] || fail "could not add the paints to the script"

# 1. Sculpt with a checkpoint every 1.5 simulated seconds, and kill -9 once the journal has been
#    rotated twice and holds records after that. A kill that lands right after a rotation leaves
#    a journal with no records (recovery gives the base); that case is tried again, up to 3 times.
attempt=0
while :; do
    attempt=$((attempt + 1))
    rm -rf "$tmp/s" "$tmp/s2"
    "$bin" sculpt --device sim --script "$script" --out "$tmp/s" --quiet \
        --autosave-s "$autosave_s" --checkpoint-s 1.5 &
    pid=$!
    polls=0
    while :; do
        size=$(stat -c %s "$tmp/s/journal.log" 2>/dev/null || echo 0)
        # base 2 written and base 1 deleted: the rotation is complete, journal.log the new one
        [ -e "$tmp/s/journal-base-2.argil" ] && [ ! -e "$tmp/s/journal-base-1.argil" ] &&
            [ "$size" -gt 50000 ] && break
        kill -0 "$pid" 2>/dev/null || fail "the session ended before its journal held records"
        polls=$((polls + 1))
        [ "$polls" -lt 6000 ] || fail "no journal records after 60 s"
        sleep 0.01
    done
    kill_ms=$(now_ms)
    kill -9 "$pid"
    status=0
    wait "$pid" || status=$?
    pid=
    [ "$status" = 137 ] || fail "the session was not killed in the middle (exit status $status)"
    [ -e "$tmp/s/final.ply" ] && fail "final.ply exists: the kill came after the session ended"
    [ -s "$tmp/s/journal.log" ] || fail "no journal after the kill"
    ls "$tmp/s"/journal-base-*.argil >/dev/null 2>&1 || fail "no base snapshot after the kill"
    edits=$("$bin" sculpt --out "$tmp/s" --quiet </dev/null 2>&1 |
        sed -n 's/.*unfinished session in .* (\([0-9]*\) edits.*/\1/p')
    [ -n "$edits" ] || fail "no offer to recover after the kill"
    [ "$edits" -gt 0 ] && break
    echo "attempt $attempt: killed right after a rotation (0 records); again"
    [ "$attempt" -lt 3 ] || fail "3 kills in a row landed right after a rotation"
done
cp -r "$tmp/s" "$tmp/s2"

# 2. The next start in that directory offers recovery (stdin is not a tty: no prompt) and leaves
#    the journal alone.
status=0
"$bin" sculpt --device sim --script "$script" --out "$tmp/s" --quiet \
    </dev/null 2>"$tmp/offer" || status=$?
cat "$tmp/offer"
[ "$status" = 1 ] || fail "a start over an unfinished session exited $status, not 1"
grep -q "found an unfinished session in $tmp/s ([0-9]* edits, last at [0-9.]* s); run 'argil recover $tmp/s'" \
    "$tmp/offer" || fail "no offer to recover"
[ "$(wc -l <"$tmp/offer")" = 1 ] || fail "the offer is not one line"
[ -s "$tmp/s/journal.log" ] || fail "the refused start touched the journal"

# 3. Recover.
"$bin" recover "$tmp/s" -o "$tmp/rec.argil" >"$tmp/rec.txt" || { cat "$tmp/rec.txt"; fail "recover failed"; }
cat "$tmp/rec.txt"
first=$(sed -n 's/.*journal records *[0-9]* (numbers \([0-9]*\)\.\.[0-9]*).*/\1/p' "$tmp/rec.txt")
last=$(sed -n 's/.*journal records *[0-9]* (numbers [0-9]*\.\.\([0-9]*\)).*/\1/p' "$tmp/rec.txt")
count=$(sed -n 's/.*journal records *\([0-9]*\) (numbers.*/\1/p' "$tmp/rec.txt")
wall_ms=$(sed -n 's/.*last record written .*(unix ms \([0-9]*\)).*/\1/p' "$tmp/rec.txt")
[ -n "$first" ] && [ -n "$last" ] && [ -n "$count" ] && [ -n "$wall_ms" ] ||
    fail "cannot read the recovery summary"
grep -Eq "base snapshot .*journal-base-([2-9]|[1-9][0-9]+)\.argil \(checkpoint" "$tmp/rec.txt" ||
    fail "recovery did not start from a rotated base"
[ "$first" -gt 1 ] || fail "a rotated journal starts at record $first"
[ "$count" = "$((last - first + 1))" ] || fail "records $first..$last expected, $count recovered"
[ "$count" -ge 5 ] || fail "only $count records after the last checkpoint"
[ -s "$tmp/rec.argil" ] && [ -s "$tmp/rec.ply" ] || fail "recover wrote no model or no mesh"
[ -e "$tmp/s/journal.log" ] && fail "recover kept the journal"
"$bin" info "$tmp/rec.argil" >"$tmp/rec.info" || fail "the recovered model does not read back"
cat "$tmp/rec.info"
# The paint came before the rotations: it is in the base, and the recovered model holds it.
grep -q "format version 2" "$tmp/rec.info" || fail "the recovered model holds no painted material"
stiff=$(sed -n 's/.*painted   stiffness scale [0-9.]* \.\. \([0-9.]*\) on \([0-9]*\) samples.*/\1 \2/p' "$tmp/rec.info")
mass=$(sed -n 's/.*painted   mass scale \([0-9.]*\) \.\. [0-9.]* on \([0-9]*\) samples.*/\1 \2/p' "$tmp/rec.info")
[ -n "$stiff" ] && [ -n "$mass" ] || fail "argil info shows no painted stiffness and mass"
echo "recovered paint: stiffness max and samples: $stiff; mass min and samples: $mass"
# 4x near the tip (>= 3.6 with the tip up to 1.08 mm from a sample), over a 10 mm ball (~2145
# samples); 0.5x likewise (<= 0.57), over an 8 mm ball (~1098 samples).
echo "$stiff $mass" | awk '{ exit !($1 >= 3.6 && $1 <= 4 && $2 > 1800 && $2 < 2500 &&
                                    $3 >= 0.5 && $3 <= 0.57 && $4 > 900 && $4 < 1300) }' ||
    fail "the recovered paint is not the painted 4x stiffness and 0.5x mass"

# 4. The reference: the same script, replayed deterministically, dumps the model at record $last.
"$bin" sculpt --device sim --script "$script" --out "$tmp/ref" --quiet \
    --debug-journal-dump "$last" "$tmp/ref.argil"
cmp "$tmp/ref.argil" "$tmp/rec.argil" || fail "the recovered model differs from the model at record $last"
"$bin" info "$tmp/ref.argil" | grep "painted" >"$tmp/ref.paint"
grep "painted" "$tmp/rec.info" | cmp -s - "$tmp/ref.paint" ||
    fail "the recovered paint differs from the paint at record $last"
echo "recovered model = model at journal record $last, byte for byte ($(stat -c %s "$tmp/rec.argil") bytes)"
# ... and the comparison can tell records apart: the model one record earlier differs.
"$bin" sculpt --device sim --script "$script" --out "$tmp/ref2" --quiet \
    --debug-journal-dump "$((last - 1))" "$tmp/ref_prev.argil"
cmp -s "$tmp/ref_prev.argil" "$tmp/rec.argil" && fail "records $((last - 1)) and $last give the same model"

# 5. Work at risk: the last durable record was made at most the autosave interval before the
#    kill (plus 100 ms for one solve step and scheduling on a busy machine).
at_risk_ms=$((kill_ms - wall_ms))
echo "work at risk: ${at_risk_ms} ms (autosave interval ${autosave_s} s)"
[ "$at_risk_ms" -ge 0 ] || fail "the last record is later than the kill"
limit_ms=$(awk -v a="$autosave_s" 'BEGIN { print int(a * 1000 + 100) }')
[ "$at_risk_ms" -le "$limit_ms" ] || fail "${at_risk_ms} ms of work lost, more than ${limit_ms} ms"

# 6. Paint journaled, not only in a base: no rotation (--checkpoint-s 3600), killed once the
#    journal holds 2 MB (the paints, ~1.6 s into the session, are in its records by 1.4 MB):
#    recovery replays them (record type 2) and equals the model at the last record, paint and all.
rm -rf "$tmp/p"
"$bin" sculpt --device sim --script "$script" --out "$tmp/p" --quiet --autosave-s "$autosave_s" \
    --checkpoint-s 3600 &
pid=$!
polls=0
while [ "$(stat -c %s "$tmp/p/journal.log" 2>/dev/null || echo 0)" -lt 2000000 ]; do
    kill -0 "$pid" 2>/dev/null || fail "the session ended before its journal held 2 MB"
    polls=$((polls + 1))
    [ "$polls" -lt 6000 ] || fail "the journal did not reach 2 MB in 60 s"
    sleep 0.01
done
kill -9 "$pid"
wait "$pid" || true
pid=
[ -e "$tmp/p/journal-base-1.argil" ] && fail "the journal was rotated despite --checkpoint-s 3600"
"$bin" recover "$tmp/p" -o "$tmp/prec.argil" >"$tmp/prec.txt" || { cat "$tmp/prec.txt"; fail "recover (paint) failed"; }
cat "$tmp/prec.txt"
painted=$(sed -n 's/.*painted material *\([0-9]*\) values replayed.*/\1/p' "$tmp/prec.txt")
plast=$(sed -n 's/.*journal records *[0-9]* (numbers [0-9]*\.\.\([0-9]*\)).*/\1/p' "$tmp/prec.txt")
[ -n "$painted" ] && [ -n "$plast" ] || fail "cannot read the paint recovery summary"
# 2154 stiffness + 1088 mass samples painted (10 mm and 8 mm balls at 1.25 mm spacing).
[ "$painted" -gt 3000 ] && [ "$painted" -lt 4000 ] ||
    fail "$painted painted values replayed, expected the ~3240 the two paints set"
"$bin" sculpt --device sim --script "$script" --out "$tmp/pref" --quiet \
    --debug-journal-dump "$plast" "$tmp/pref.argil"
cmp "$tmp/pref.argil" "$tmp/prec.argil" ||
    fail "the recovered painted model differs from the model at record $plast"
echo "painted model recovered from the journal's records = model at record $plast ($painted painted values)"

# 7. --discard-journal starts over, and a clean end leaves no journal behind.
"$bin" sculpt --device sim --script "$script" --out "$tmp/s2" --quiet \
    --discard-journal </dev/null 2>"$tmp/discard" || { cat "$tmp/discard"; fail "--discard-journal"; }
grep -q "discarded" "$tmp/discard" || fail "no word about the discarded journal"
[ -s "$tmp/s2/final.ply" ] || fail "the new session wrote no final.ply"
ls "$tmp/s2" | grep -q '^journal' && fail "a clean end left journal files: $(ls "$tmp/s2")"
echo "crash recovery: all checks passed"
