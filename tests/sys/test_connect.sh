#!/bin/sh
# `argil connect` against the real board daemon over real UDP on 127.0.0.1, as a person runs it:
#   1. bad device strings and options: one line on stderr, exit 2; a missing USB board: exit 1;
#   2. a 3 s armed session: the board reaches ACTIVE; the link loses no telemetry (one CSV row
#      for every board tick from the first to the last: rows = tick span, ±0.5 %), the rate is
#      the board's 1 kHz within what a shared machine allows (1500..3050 rows in 3 s: the daemon
#      runs without RT priority here and slows under load — 713/s and 750/s measured at load 8 on 2
#      cores, 999/s idle); no decode errors; the clay and the CSV are written;
#   3. the daemon is killed and restarted mid-session: connect, not restarted, sees the
#      restart, says HELLO again and the board is ACTIVE a second time; still no decode errors;
#   3b. the host stalls 0.5 s: the board faults (host lost) and is re-armed when the link is back;
#   4. Ctrl-C (SIGINT) ends a session cleanly: exit 130 and the files are there.
set -eu
bin="$REL/argil"
board="$REL/argil-board"
tmp=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# 1. One line on stderr and the expected status, within 5 s.
expect_error() {
    want=$1; pattern=$2; shift 2
    st=0
    timeout 5 "$bin" connect "$@" >"$tmp/out" 2>"$tmp/err" || st=$?
    [ "$st" = 124 ] && fail "'connect $*' hung"
    [ "$st" = "$want" ] || fail "'connect $*' exit $st, want $want: $(cat "$tmp/err")"
    [ "$(wc -l <"$tmp/err")" = 1 ] || fail "'connect $*' printed $(wc -l <"$tmp/err") lines: $(cat "$tmp/err")"
    grep -q -- "$pattern" "$tmp/err" || fail "'connect $*' said: $(cat "$tmp/err")"
    echo "ok: connect $* -> $(cat "$tmp/err")"
}
"$bin" connect --help >"$tmp/help" || fail "--help exits non-zero"
for opt in device seconds arm telemetry out quiet; do
    grep -q -- "--$opt" "$tmp/help" || fail "--help does not explain --$opt"
done
grep -q "exit status" "$tmp/help" || fail "--help does not document the exit status"
expect_error 2 "bad device 'bogus': unknown kind" --device bogus --out "$tmp/o"
expect_error 2 "bad device 'udp:127.0.0.1': expected udp:HOST:PORT" --device udp:127.0.0.1 --out "$tmp/o"
expect_error 2 "the UDP port must be a whole number 1..65535" --device udp:127.0.0.1:70000 --out "$tmp/o"
expect_error 2 "1 to 4 hex digits" --device usb:12345:1 --out "$tmp/o"
expect_error 2 "each USB port must be a number" --device usb:1-x --out "$tmp/o"
expect_error 2 "'sim' takes nothing after it but ':press'" --device sim:fast --out "$tmp/o"
expect_error 2 "unknown option '--frobnicate'" --frobnicate
expect_error 2 "--seconds must be a number > 0" --device sim --seconds -1
expect_error 1 "usb 1209:0001: no such device\|usb: cannot start libusb" --device usb --seconds 1 --out "$tmp/o"

number_after() { sed -n "s/.*$1 \([0-9][0-9]*\).*/\1/p" "$tmp/$2" | head -n 1; }

# The link is keyed, as a board on a network should be (docs/link.md); the unkeyed cases are
# tests/sys/test_link_key.sh's.
"$bin" keygen "$tmp/link.key" >/dev/null || fail "argil keygen"
start_board() {
    # --host-timeout-ms 250: on this shared, non-RT test machine the host stalls for more than
    # the default 50 ms now and then; the fault and re-arm path is exercised on purpose in 3b.
    "$board" --bus sim --link "udp:127.0.0.1:$port" --rate-hz 1000 --overrun-streak 0 \
        --rt-priority 0 --stats-period-s 0 --host-timeout-ms 250 --key "$tmp/link.key" \
        >>"$tmp/daemon.out" 2>>"$tmp/daemon.err" &
    pid=$!
}
port=$((21000 + $$ % 20000))

# 2. A steady session.
start_board
sleep 0.3
st=0
"$bin" connect --device "udp:127.0.0.1:$port" --key "$tmp/link.key" --seconds 3 --arm --out "$tmp/s1" \
    >"$tmp/s1.out" 2>"$tmp/s1.err" || st=$?
cat "$tmp/s1.out"
[ "$st" = 0 ] || fail "steady session exit $st: $(tail -n 3 "$tmp/s1.err")"
grep -q "^connect .* link connected .* board ACTIVE" "$tmp/s1.err" ||
    fail "no status line showing the board ACTIVE: $(cat "$tmp/s1.err")"
rows=$(number_after "telemetry rows" s1.out)
csv_rows=$(($(wc -l <"$tmp/s1/telemetry.csv") - 1))
span=$(awk -F, 'NR == 2 { f = $14 } NR > 1 { l = $14 } END { print l - f + 1 }' "$tmp/s1/telemetry.csv")
decode=$(number_after "decode errors" s1.out)
active=$(number_after "ACTIVE entered" s1.out)
echo "steady: $rows telemetry rows in 3 s ($span board ticks from first to last row), $csv_rows CSV rows, decode errors $decode, ACTIVE entered $active"
[ "$rows" -ge 1500 ] && [ "$rows" -le 3050 ] || fail "telemetry rows $rows, want 1500..3050 (1 kHz)"
[ "$csv_rows" = "$rows" ] || fail "CSV has $csv_rows rows, summary says $rows"
[ $((rows * 1000)) -ge $((span * 995)) ] && [ "$rows" -le "$span" ] ||
    fail "the link lost telemetry: $rows rows for $span board ticks"
[ "$decode" = 0 ] || fail "$decode decode errors"
[ "$active" -ge 1 ] || fail "the board never became ACTIVE"
grep -q ",ACTIVE," "$tmp/s1/telemetry.csv" || fail "no ACTIVE row in the CSV"
[ -s "$tmp/s1/final.ply" ] && [ -s "$tmp/s1/model.argil" ] || fail "final.ply / model.argil missing"
"$bin" info "$tmp/s1/model.argil" >/dev/null || fail "model.argil does not read back"

# 3. The daemon restarts mid-session; connect keeps running and resynchronises.
"$bin" connect --device "udp:127.0.0.1:$port" --key "$tmp/link.key" --seconds 7 --arm --out "$tmp/s2" \
    >"$tmp/s2.out" 2>"$tmp/s2.err" &
cpid=$!
sleep 2.5
kill -TERM "$pid"
wait "$pid" || true
pid=
sleep 0.5
start_board
st=0
wait "$cpid" || st=$?
cat "$tmp/s2.out"
[ "$st" = 0 ] || fail "restart session exit $st: $(tail -n 3 "$tmp/s2.err")"
grep -q "link lost" "$tmp/s2.err" || echo "note: the loss fell between two status lines"
active=$(number_after "ACTIVE entered" s2.out)
restarts=$(number_after "restarts seen" s2.out)
hellos=$(number_after "board HELLOs" s2.out)
reconnects=$(number_after "reconnects" s2.out)
decode=$(number_after "decode errors" s2.out)
echo "restart: ACTIVE entered $active, restarts seen $restarts, board HELLOs $hellos, link reconnects $reconnects, decode errors $decode"
[ "$active" -ge 2 ] || fail "the board was not ACTIVE again after its restart"
[ "$restarts" -ge 1 ] || fail "the restart went unnoticed"
[ "$hellos" -ge 2 ] || fail "no HELLO exchange after the restart"
[ "$reconnects" -ge 1 ] || fail "the link never went lost and back"
[ "$decode" = 0 ] || fail "$decode decode errors"
grep -q "^  board               ACTIVE;" "$tmp/s2.out" || fail "the session did not end with the board ACTIVE"
tail -n 1 "$tmp/s2/telemetry.csv" | grep -q ",ACTIVE," || fail "the last CSV row is not ACTIVE"

# 3b. The host stalls (SIGSTOP 0.5 s, like a pulled cable): the board faults (host lost); when
#     the host is back the link reconnects and, as --arm was asked for, the board is re-armed.
"$bin" connect --device "udp:127.0.0.1:$port" --key "$tmp/link.key" --seconds 4 --arm --out "$tmp/s4" \
    >"$tmp/s4.out" 2>"$tmp/s4.err" &
cpid=$!
sleep 1.8
kill -STOP "$cpid"
sleep 0.5
kill -CONT "$cpid"
st=0
wait "$cpid" || st=$?
[ "$st" = 0 ] || fail "stalled-host session exit $st: $(tail -n 3 "$tmp/s4.err")"
faults=$(number_after "faults" s4.out)
active=$(number_after "ACTIVE entered" s4.out)
echo "stalled host: board faults $faults, ACTIVE entered $active, $(grep -c ',FAULT,' "$tmp/s4/telemetry.csv") FAULT rows"
[ "$faults" -ge 1 ] && grep -q ",FAULT," "$tmp/s4/telemetry.csv" || fail "the board did not fault while the host was stopped"
[ "$active" -ge 2 ] || fail "the board was not re-armed after the host came back"
grep -q "^  board               ACTIVE;" "$tmp/s4.out" || fail "the session did not end ACTIVE"

# 4. Ctrl-C.
"$bin" connect --device "udp:127.0.0.1:$port" --key "$tmp/link.key" --out "$tmp/s3" >"$tmp/s3.out" 2>"$tmp/s3.err" &
cpid=$!
sleep 1.5
kill -INT "$cpid"
st=0
wait "$cpid" || st=$?
[ "$st" = 130 ] || fail "Ctrl-C exit $st, want 130: $(tail -n 3 "$tmp/s3.err")"
grep -q "(interrupted)" "$tmp/s3.out" || fail "no interrupted summary"
[ -s "$tmp/s3/telemetry.csv" ] && [ -s "$tmp/s3/final.ply" ] || fail "files missing after Ctrl-C"
echo "ok: Ctrl-C -> exit 130, $(($(wc -l <"$tmp/s3/telemetry.csv") - 1)) telemetry rows written"

kill -TERM "$pid"
wait "$pid" || true
pid=
echo "argil connect: bad devices are one line; UDP session at 1 kHz; a board restart is resynchronised; Ctrl-C writes the files"
