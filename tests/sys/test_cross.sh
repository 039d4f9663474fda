#!/bin/sh
# The cross tier (make cross): the core's unit tests and one SIL scenario built for aarch64 run
# under qemu-aarch64, the aarch64 argil-board answers --help and runs a UDP session on the simulated
# arm, and the Cortex-M image boots on qemu-system-arm (mps2-an386, Cortex-M4; the M7 build on
# mps2-an500) and produces the host build's tick results for the same inputs:
#   state, fault, CAN frame count, GPIO levels, link bytes: identical;
#   commanded torque: within 1 per mille; rendered force: within 2 mN per axis
# (newlib's and glibc's sinf/cosf differ in the last bit; fused multiply-add is off).
# Each aarch64 cmocka test and each other step is one check reported to the runner
# (tests/lib/report.sh): aarch64/BINARY/TEST, then the names below; the first failed step ends
# the script and the steps after it count as failed (PLAN).
set -eu
. tests/lib/report.sh
root=$(dirname "$REL")
a64="$root/aarch64"
cm="$root/cortexm"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The steps after the aarch64 cmocka binaries, in order; each reports PASS through ok, and the
# first that fails reports FAIL through fail and ends the script.
report_plan 7
step=a64-board-help
ok() { report PASS "$step" "$*"; }
fail() { report FAIL "$step" "$*"; exit 1; }
# The loader (-L: ld-linux-aarch64.so.1 of libc6-arm64-cross, the glibc the cross gcc links
# against) and libc.so.6 must come from the same glibc build: the cross sysroot's lib first, then
# Debian's arm64 multiarch directory for libgpiod and libcmocka only. With the multiarch
# libc.so.6 (2.36-9+deb12uN) under the cross loader (2.36-8cross1) their private _rtld_global
# layouts differ and the first pthread_create spins forever walking the stack cache list
# (docs/board.md, "aarch64 under qemu-user").
QEMU_A64="qemu-aarch64 -L /usr/aarch64-linux-gnu -E LD_LIBRARY_PATH=/usr/aarch64-linux-gnu/lib:/usr/lib/aarch64-linux-gnu"

# Every test of every binary is a check; one that crashes or hangs has its unrun tests failed.
n=0 bad=""
for t in "$a64"/tests/test_* "$a64"/sil/test_*; do
    [ -x "$t" ] || continue
    st=0
    timeout -s KILL 300 $QEMU_A64 "$t" >"$tmp/out" 2>&1 || st=$?
    cmocka_results "aarch64/$(basename "$t")/" <"$tmp/out" >"$tmp/res"
    [ -z "${RESULTS_FILE:-}" ] || cat "$tmp/res" >>"$RESULTS_FILE"
    echo "aarch64 $(basename "$t"): $(grep -c '^PASS' "$tmp/res") passed, $(grep -c '^FAIL' "$tmp/res") failed, $(grep -c '^SKIP' "$tmp/res") skipped (status $st)"
    [ "$st" = 0 ] || { tail -n 20 "$tmp/out"; bad="$bad $(basename "$t")"; }
    # Dead before cmocka said how many tests it has: one failed check for the binary.
    [ "$st" = 0 ] || grep -q '^PLAN' "$tmp/res" || report FAIL "aarch64/$(basename "$t")" "status $st before its first test"
    n=$((n + 1))
done
[ "$n" -ge 2 ] || { report FAIL aarch64-tests "no aarch64 tests were built"; exit 1; }
[ -z "$bad" ] || echo "aarch64 tests failed:$bad"

timeout -s KILL 60 $QEMU_A64 "$a64/argil-board" --help >"$tmp/help" || fail "aarch64 argil-board --help"
grep -q -- '--rate-hz' "$tmp/help" || fail "aarch64 --help incomplete"
ok "aarch64 argil-board --help lists --rate-hz"
step=a64-board-bad-port
st=0
timeout -s KILL 60 $QEMU_A64 "$a64/argil-board" --bus sim --link udp:127.0.0.1:0 >/dev/null 2>"$tmp/err" || st=$?
[ "$st" = 2 ] || fail "aarch64 argil-board: bad port gave status $st"
ok "port 0 refused with status 2"

# The aarch64 daemon's real loop (SCHED_FIFO 80, mlockall, absolute clock_nanosleep, the UDP link
# thread) under qemu-user, with the native host peer over real UDP: HELLO, window, arm, ACTIVE;
# host loss; reconnection, over a keyed link (the aarch64 libsodium's tags checked by the native
# one's). Emulated ticks overrun now and then, so no overrun-streak fault here.
step=a64-udp-session
port=$((40000 + $$ % 20000))
"$REL/argil" keygen "$tmp/link.key" >/dev/null || fail "argil keygen"
$QEMU_A64 "$a64/argil-board" --bus sim --link "udp:127.0.0.1:$port" --duration-s 60 \
    --stats-period-s 0 --overrun-streak 0 --key "$tmp/link.key" >"$tmp/a64d.out" 2>"$tmp/a64d.err" &
dpid=$!
trap 'kill "$dpid" 2>/dev/null; rm -rf "$tmp"' EXIT
i=0
until grep -q "running at" "$tmp/a64d.err"; do
    kill -0 "$dpid" 2>/dev/null || { cat "$tmp/a64d.err"; fail "aarch64 argil-board exited at start-up"; }
    i=$((i + 1)); [ "$i" -le 300 ] || { kill -KILL "$dpid"; fail "aarch64 argil-board: no start-up line in 30 s (stalled)"; }
    sleep 0.1
done
st=0
ARGIL_LINK_KEY="$tmp/link.key" timeout -s KILL 60 "$REL/board_udp_client" "$port" 30 >"$tmp/a64c.out" 2>&1 || st=$?
sed 's/^/aarch64 daemon, native host: /' "$tmp/a64c.out"
kill -TERM "$dpid" 2>/dev/null || true
dst=0; wait "$dpid" || dst=$?
grep -q "^phase 1: ACTIVE after [0-9]* ms" "$tmp/a64c.out" || { cat "$tmp/a64d.err"; fail "aarch64 argil-board never became ACTIVE"; }
[ "$st" = 0 ] || { cat "$tmp/a64d.err"; fail "aarch64 UDP session (client status $st)"; }
[ "$dst" = 0 ] || { cat "$tmp/a64d.err"; fail "aarch64 daemon exit $dst after SIGTERM"; }
grep "exit: [0-9]* ticks" "$tmp/a64d.err" | cut -c1-160 | sed 's/^/aarch64 /'
trap 'rm -rf "$tmp"' EXIT
ok "$(grep "^phase 1: ACTIVE after" "$tmp/a64c.out" | head -n 1); host loss and reconnection"

step=tick-ref
"$cm/tick_ref" >"$tmp/ref.txt" || fail "host tick reference"
ok "$(tail -n 1 "$tmp/ref.txt")"
compare() {
    awk -v name="$1" '
        FNR == NR { ref[FNR] = $0; nref = FNR; next }
        {
            split(ref[FNR], r, " ")
            if (NF != split(ref[FNR], r, " ")) { print name ": line " FNR " differs in shape"; bad = 1; exit }
            if ($1 == "done:") { if ($0 != ref[FNR]) { print name ": summary differs"; bad = 1 } next }
            for (i = 1; i <= 5; i++) if ($i != r[i]) { print name ": tick " $1 " field " i " " $i " vs " r[i]; bad = 1; exit }
            if ($12 != r[12]) { print name ": tick " $1 " link bytes differ"; bad = 1; exit }
            for (i = 6; i <= 8; i++) { d = $i - r[i]; if (d < 0) d = -d; if (d > 1) { print name ": tick " $1 " torque " d; bad = 1; exit } if (d > mt) mt = d }
            for (i = 9; i <= 11; i++) { d = $i - r[i]; if (d < 0) d = -d; if (d > 0.002) { print name ": tick " $1 " force " d " N"; bad = 1; exit } if (d > mf) mf = d }
            if ($0 != ref[FNR]) diff++
            n++
        }
        END {
            if (n + 1 != nref) { print name ": " n + 1 " lines, reference " nref; bad = 1 }
            printf "%s: %d ticks, states/frames/GPIO identical, %d lines not bit-identical, max |dtorque| %d per mille, max |dF| %.2g N\n", name, n, diff, mt, mf
            exit bad
        }' "$tmp/ref.txt" "$2"
}
for board in m4:mps2-an386 m7:mps2-an500; do
    cpu=${board%%:*}; machine=${board#*:}
    step=cortex-$cpu-ticks
    start=$(date +%s.%N)
    timeout -s KILL 60 qemu-system-arm -M "$machine" -nographic -semihosting -kernel "$cm/argil-$cpu.elf" \
        >"$tmp/$cpu.txt" 2>"$tmp/$cpu.err" || { tail -n 5 "$tmp/$cpu.txt" "$tmp/$cpu.err"; fail "$cpu image on $machine"; }
    end=$(date +%s.%N)
    compare "cortex-$cpu on $machine ($(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f s", b - a }'))" "$tmp/$cpu.txt" >"$tmp/cmp" ||
        { cat "$tmp/cmp"; fail "cortex-$cpu results: $(head -n 1 "$tmp/cmp")"; }
    ok "$(cat "$tmp/cmp")"
done

# The MCU link refuses the heap and printf in the core.
step=cortex-m-no-malloc
printf '#include <stdlib.h>\nvoid *core_bad(void);\nvoid *core_bad(void) { return malloc(8); }\n' >"$tmp/bad.c"
arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -c "$tmp/bad.c" -o "$tmp/bad.o"
arm-none-eabi-ld -r -o "$tmp/core.o" "$tmp/bad.o" "$cm/m4/core.o"
arm-none-eabi-objcopy --redefine-sym malloc=argil_core_must_not_call_malloc "$tmp/core.o" "$tmp/core2.o"
if arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard --specs=rdimon.specs \
    -T firmware/cortexm/mps2.ld -Wl,--gc-sections -Wl,--undefined=core_bad \
    "$cm/m4/firmware/cortexm/startup.o" "$cm/m4/firmware/cortexm/tick_script.o" \
    "$cm/m4/firmware/cortexm/tick_main.o" "$tmp/core2.o" -lm -o "$tmp/bad.elf" 2>"$tmp/link.err"; then
    fail "the Cortex-M link accepted malloc in the core"
fi
grep -q argil_core_must_not_call_malloc "$tmp/link.err" || fail "no clear link error: $(cat "$tmp/link.err")"
ok "a core that calls malloc does not link ($(grep -o "undefined reference to .argil_core_must_not_call_malloc." "$tmp/link.err" | head -1))"
# A failed aarch64 test fails the script as well as its own check.
[ -z "$bad" ] || exit 1
