#!/bin/sh
# The UDP link's key, as a person meets it (docs/link.md "Link key"): argil keygen makes an
# owner-only file and never overwrites one; a key file others may read is refused in one line
# naming the fix (board and host); a board without a key refuses `argil connect --arm` with a
# clear line and never arms, and says so at start and at exit; with --insecure it arms and logs
# INSECURE at start and in every stats line; a keyed board refuses a host with another key (the
# host says why, the board counts every datagram as a bad tag) and serves the host with its key;
# a keyed host meets a keyless board with a clear line instead of a silent wait.
set -eu
tmp=$(mktemp -d)
bpid=
trap '[ -n "$bpid" ] && kill "$bpid" 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
argil="$REL/argil"
port=$((23000 + $$ % 20000))

# keygen
"$argil" keygen --help | grep -q "usage: argil keygen FILE" || fail "keygen --help"
"$argil" keygen "$tmp/a.key" >/dev/null || fail "keygen"
[ "$(stat -c %a "$tmp/a.key")" = 600 ] || fail "keygen wrote mode $(stat -c %a "$tmp/a.key")"
grep -Eq '^[0-9a-f]{64}$' "$tmp/a.key" || fail "no line of 64 hex digits: $(cat "$tmp/a.key")"
cp -p "$tmp/a.key" "$tmp/a.copy"
st=0; "$argil" keygen "$tmp/a.key" 2>"$tmp/err" || st=$?
[ "$st" = 1 ] && grep -q "never overwritten" "$tmp/err" || fail "keygen over a file: exit $st, $(cat "$tmp/err")"
cmp -s "$tmp/a.key" "$tmp/a.copy" || fail "keygen changed an existing key file"
"$argil" keygen "$tmp/b.key" >/dev/null
cmp -s "$tmp/a.key" "$tmp/b.key" && fail "two keygens gave the same key"
cp "$tmp/a.key" "$tmp/open.key"; chmod 644 "$tmp/open.key"
st=0; "$argil" connect --device "udp:127.0.0.1:$port" --key "$tmp/open.key" --seconds 1 \
    --out "$tmp/o" --no-journal >/dev/null 2>"$tmp/err" </dev/null || st=$?
[ "$st" = 2 ] && [ "$(wc -l <"$tmp/err")" = 1 ] && grep -q "chmod 600 $tmp/open.key" "$tmp/err" ||
    fail "connect with a 0644 key: exit $st, $(cat "$tmp/err")"
st=0; "$argil" connect --device sim --key "$tmp/a.key" --seconds 1 --out "$tmp/o" \
    --no-journal >/dev/null 2>"$tmp/err" </dev/null || st=$?
[ "$st" = 2 ] && grep -q "key is for udp: devices" "$tmp/err" || fail "--key with sim: exit $st, $(cat "$tmp/err")"

# start_board ARGS...: argil-board on the simulated arm, 1 s stats lines
start_board() {
    "$REL/argil-board" --bus sim --link "udp:127.0.0.1:$port" --rt-priority 0 --overrun-streak 0 \
        --stats-period-s 1 --host-timeout-ms 250 --duration-s 20 "$@" >/dev/null 2>"$tmp/board.err" &
    bpid=$!
    sleep 0.3
}
stop_board() {
    kill -TERM "$bpid"; st=0; wait "$bpid" || st=$?; bpid=
    [ "$st" = 0 ] || fail "daemon exit $st: $(cat "$tmp/board.err")"
    port=$((port + 1))
}
connect() { # connect OUT ARGS...: exit status in $st
    out=$1; shift
    st=0
    timeout 20 "$argil" connect --device "udp:127.0.0.1:$port" --out "$tmp/$out" --no-journal \
        "$@" >"$tmp/$out.out" 2>"$tmp/$out.err" </dev/null || st=$?
}

# 1. no key, no --insecure: ARM refused, the host told how to fix it, the board never armed
start_board
connect nokey --arm --seconds 6
grep -q "the UDP link has no key: ARM over it is refused" "$tmp/board.err" || fail "no start line: $(head -3 "$tmp/board.err")"
[ "$st" = 1 ] || fail "connect --arm on a keyless board: exit $st"
grep -q "^argil connect: the board refuses to arm over UDP without a link key: start argil-board with --key FILE (argil keygen FILE)" \
    "$tmp/nokey.err" || fail "connect's message: $(tail -n 2 "$tmp/nokey.err")"
stop_board
grep -q "state ARMED\|state ACTIVE" "$tmp/board.err" && fail "the keyless board armed: $(grep state "$tmp/board.err")"
grep -q "ARM refused (1 so far)" "$tmp/board.err" || fail "the board did not log the refusal: $(cat "$tmp/board.err")"
grep -q "exit: .*; ARM refused [1-9]" "$tmp/board.err" || fail "no ARM refused count at exit"
echo "no key: connect --arm refused in one line (exit 1), the board never armed and counted it"

# 2. --insecure: it arms; INSECURE at start and in every stats line
start_board --insecure
connect insecure --arm --seconds 4
[ "$st" = 0 ] || fail "connect --arm on an --insecure board: exit $st: $(tail -n 2 "$tmp/insecure.err")"
grep -q "^  board               ACTIVE;" "$tmp/insecure.out" || fail "the --insecure board did not arm"
sleep 1.2
stop_board
grep -q "^argil-board: INSECURE: the UDP link has no key" "$tmp/board.err" || fail "no INSECURE line at start"
n_stats=$(grep -c "^argil-board: stats: .* ticks at" "$tmp/board.err")
n_insecure=$(grep -c "^argil-board: stats: INSECURE" "$tmp/board.err")
[ "$n_stats" -ge 3 ] && [ "$n_stats" = "$n_insecure" ] || fail "$n_insecure INSECURE lines in $n_stats stats lines"
grep -q "^argil-board: exit: INSECURE" "$tmp/board.err" || fail "no INSECURE line at exit"
echo "--insecure: armed (ACTIVE); INSECURE at start, in all $n_stats stats lines and at exit"

# 3. a keyed board: another key is refused (host's line, board's count), its own key served
start_board --key "$tmp/a.key"
connect wrong --arm --seconds 3 --key "$tmp/b.key"
[ "$st" = 1 ] && grep -q "the board never answered on udp:127.0.0.1:$port; a board answers a host with --key only when started with --key and the same key file" \
    "$tmp/wrong.err" || fail "connect with another key: exit $st, $(tail -n 2 "$tmp/wrong.err")"
connect nohostkey --seconds 3
[ "$st" = 1 ] && grep -q "a board started with --key answers only a host given the same key file" "$tmp/nohostkey.err" ||
    fail "connect without a key to a keyed board: exit $st, $(tail -n 2 "$tmp/nohostkey.err")"
connect right --arm --seconds 3 --key "$tmp/a.key"
[ "$st" = 0 ] && grep -q "^  board               ACTIVE;" "$tmp/right.out" ||
    fail "connect with the board's key: exit $st, $(tail -n 2 "$tmp/right.err")"
# (the board's counts are since it started: the bad tags are the two hosts' before)
grep -q "board link .* bad tag [1-9][0-9]*, bad nonce 0; ARM refused 0" "$tmp/right.out" || fail "$(grep 'board link' "$tmp/right.out")"
stop_board
bad=$(sed -n 's/^argil-board: exit: host sessions.* bad tag \([0-9]*\),.*/\1/p' "$tmp/board.err")
[ "${bad:-0}" -ge 10 ] || fail "the keyed board counted $bad bad tags from the hosts without its key"
grep -q "refusing UDP datagrams whose tag does not verify" "$tmp/board.err" || fail "no log line for the bad tags"
echo "keyed board: another key and none refused ($bad bad tags, each host told why), its own key ACTIVE"

# 4. a keyed host and a keyless board: a clear line, not a silent wait
start_board
connect keyed_host --seconds 3 --key "$tmp/a.key"
cst=$st
stop_board
[ "$cst" = 1 ] && grep -q "a board without a key refuses tagged datagrams" "$tmp/keyed_host.err" ||
    fail "keyed host, keyless board: exit $cst, $(tail -n 2 "$tmp/keyed_host.err")"
grep -q "exit: .* bad tag [1-9]" "$tmp/board.err" || fail "the keyless board did not count the tagged datagrams"
echo "keyed host, keyless board: told why in one line; the board counted the tagged datagrams"
