#!/bin/sh
# argil-board as a new user meets it, and the real daemon over real UDP: --help names every
# option; a bad option, a bad value, a missing CAN interface, an unknown GPIO line or an
# unmounted FunctionFS each give one clear line and a non-zero exit, never a hang; then a host
# on 127.0.0.1 arms it, loses it (force fades, FAULT) and reconnects without a restart, over a
# keyed link (argil keygen; the client takes the key from ARGIL_LINK_KEY); a bad key file is one
# line naming the fix.
set -eu
bin="$REL/argil-board"
tmp=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$bin" --help >"$tmp/help" || fail "--help exits non-zero"
for opt in bus can drive-heartbeat-ms bus-recovery-ms gpio-chip line-estop line-drive-fault \
           line-btn1 line-btn2 line-drive-enable line-led line-wdog link host-timeout-ms \
           host-fade-ms rate-hz rt-priority cpu overrun-streak stats-period-s duration-s \
           max-force-n max-velocity-m-s model-scale model-offset-m key insecure config set; do
    grep -q -- "--$opt" "$tmp/help" || fail "--help does not explain --$opt"
done

# One line on stderr, the expected status, within 5 s.
. "$(dirname "$0")/expect_one_line_error.sh"
expect_error 2 "unknown option '--frobnicate'" --frobnicate 1
expect_error 2 "rate_hz '3000'" --rate-hz 3000
expect_error 2 "needs a value" --can
expect_error 2 "expected udp:ADDR:PORT or ffs:DIR" --link tcp:1.2.3.4:5
expect_error 2 "config file '$tmp/nope.ini'" --config "$tmp/nope.ini"
printf '[loop]\nrate_hz = 2000\nbogus = 1\n' >"$tmp/bad.ini"
expect_error 2 "bad.ini:3: unknown setting 'loop.bogus'" --config "$tmp/bad.ini"
expect_error 3 "CAN interface 'can7'" --can can7 --rt-priority 0
expect_error 3 "GPIO line 'NO_SUCH_LINE' not found" --bus sim --line-estop NO_SUCH_LINE --rt-priority 0
expect_error 3 "ffs:$tmp/ffs" --bus sim --link "ffs:$tmp/ffs" --rt-priority 0
"$REL/argil" keygen "$tmp/link.key" >/dev/null || fail "argil keygen"
cp "$tmp/link.key" "$tmp/open.key"; chmod 644 "$tmp/open.key"
expect_error 2 "chmod 600 $tmp/open.key" --bus sim --key "$tmp/open.key" --rt-priority 0
printf '# short\n0123\n' >"$tmp/short.key"; chmod 600 "$tmp/short.key"
expect_error 2 "short.key':2: fewer than 64 hex digits" --bus sim --key "$tmp/short.key" --rt-priority 0
expect_error 2 "argil keygen" --bus sim --key "$tmp/none.key" --rt-priority 0
expect_error 2 "link.key and link.insecure together" --bus sim --key "$tmp/link.key" --insecure
expect_error 2 "needs no key" --bus sim --link "ffs:$tmp/ffs" --key "$tmp/link.key"

# The real daemon (simulated arm behind it) and a host over UDP. 2000 Hz must work too.
port=$((20000 + $$ % 20000))
for rate in 1000 2000; do
    # --duration-s only a backstop: SIGTERM below ends it (a loaded machine must not win a race)
    "$bin" --bus sim --link "udp:127.0.0.1:$port" --rate-hz "$rate" --duration-s 60 \
        --stats-period-s 0 --overrun-streak 0 --key "$tmp/link.key" \
        >"$tmp/daemon.out" 2>"$tmp/daemon.err" &
    pid=$!
    sleep 0.3
    # 30 link ticks each way: the daemon and the client are ordinary threads on a shared,
    # non-RT test machine (the VM rig passes 6, a real board 1).
    ARGIL_LINK_KEY="$tmp/link.key" "$REL/board_udp_client" "$port" 30 >"$tmp/client.out" 2>&1 || {
        cat "$tmp/client.out"; kill "$pid"; cat "$tmp/daemon.err"; fail "UDP session at $rate Hz"; }
    cat "$tmp/client.out"
    kill -TERM "$pid"
    st=0; wait "$pid" || st=$?
    pid=
    [ "$st" = 0 ] || fail "daemon exit $st after SIGTERM: $(cat "$tmp/daemon.err")"
    grep -q "exit: .* ticks at $rate Hz" "$tmp/daemon.err" || fail "no exit statistics"
    grep -q "wake latency histogram" "$tmp/daemon.err" || fail "no latency histogram"
    grep -q "exit: .* bad tag 0, bad nonce 0; ARM refused 0" "$tmp/daemon.err" ||
        fail "the keyed session refused its own host: $(grep 'host sessions' "$tmp/daemon.err")"
    grep "exit:" "$tmp/daemon.err"
    port=$((port + 1))
done
echo "argil-board: CLI errors are one clear line; keyed UDP arm, host loss and reconnection work"
