# The HIL checks: one shell function check_<name> per kind of plan line (hil/plan.txt), shared
# by the VM and a real rig. Sourced by hil/run-plan.sh after the rig config; busybox ash or dash.
# A check calls pass/fail/skip once with its measured figure; it may leave processes running,
# run-plan.sh calls rig_cleanup after each line.
# Time: every timestamp is CLOCK_REALTIME (hil-probe, candump -L), so CAN frames, GPIO edges and
# the daemon's lines of one run share one axis.

# Priorities of the rig's own timing tools, below argil-board's threads (80 loop, 70 link).
PROBE_PRIO=${PROBE_PRIO:-50}
PROBE_PERIOD_US=${PROBE_PERIOD_US:-200}
CANDUMP_PRIO=${CANDUMP_PRIO:-$PROBE_PRIO}
HOST_PRIO=${HOST_PRIO:-60}
# argil-sim in the scenarios (the arm); a rig config may put it under the board's link thread.
SIM_PRIO=${SIM_PRIO:-$((HOST_PRIO - 1))}
# How long a scenario waits for the board to be ready to sculpt before it gives up (s).
START_TIMEOUT_S=${START_TIMEOUT_S:-60}

# ---- results ----
pass() { RESULT=PASS; DETAIL="$*"; }
fail() { RESULT=FAIL; DETAIL="$*"; }
skip() { RESULT=SKIP; DETAIL="$*"; }
have() { command -v "$1" >/dev/null 2>&1; }
# Milliseconds between two hil-probe/candump timestamps (b - a), one decimal.
ms_between() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", (b - a) * 1000 }'; }
# True when $1 <= $2 <= $3 (decimals allowed).
within() { awk -v lo="$1" -v x="$2" -v hi="$3" 'BEGIN { exit !(x >= lo && x <= hi) }'; }

# ---- GPIO through the rig ----
line_offset() { # NAME -> its offset on the board chip (gpioinfo), empty if absent
    gpioinfo "$GPIO_CHIP" 2>/dev/null | awk -v n="\"$1\"" '$3 == n { sub(":", "", $2); print $2; exit }'
}
# Looks every named line up once (gpioinfo is slow under emulation): SIMBASE_<name> is its
# gpio-sim sysfs directory. Call before the first rig_input/rig_watch.
rig_prepare() {
    [ "$STIM" = gpio-sim ] || return 0
    dev=/sys/devices/platform/$(cat "$GPIO_SIM_CONFIGFS/dev_name")/$(cat "$GPIO_SIM_CONFIGFS/bank0/chip_name")
    for l in "$LINE_ESTOP" "$LINE_DRIVE_FAULT" "$LINE_BTN1" "$LINE_BTN2" "$LINE_DRIVE_ENABLE" "$LINE_LED" "$LINE_WDOG"; do
        off=$(line_offset "$l")
        [ -n "$off" ] || { echo "hil: line $l not on chip $GPIO_CHIP" >&2; return 1; }
        eval "SIMBASE_$l=\$dev/sim_gpio$off"
    done
}
sim_attr() { eval "echo \"\${SIMBASE_$1:-/nonexistent/$1}/$2\""; } # NAME ATTR -> sysfs file
# Drives a board input line to level 0 or 1 (what the arm's e-stop, fault line or button does).
rig_input() {
    case "$STIM" in
    gpio-sim)
        if [ "$2" = 1 ]; then echo pull-up >"$(sim_attr "$1" pull)"; else echo pull-down >"$(sim_attr "$1" pull)"; fi ;;
    loopback)
        eval "off=\${LOOP_$1:?LOOP_$1 not set in the rig config}"
        [ -n "${HIL_WATCH_READY:-}" ] && : >"$HIL_WATCH_READY" # gpiomon says nothing sooner
        eval "old=\${LOOP_PID_$1:-}"
        [ -n "$old" ] && kill "$old" 2>/dev/null
        gpioset --mode=signal "$LOOP_CHIP" "$off=$2" &
        eval "LOOP_PID_$1=$!" ;;
    esac
}
# Samples a board output line for MS ms: "samples=N high=N edges=N first_edge=T last_edge=T
# final=V start=T end=T first_edge_lo=T last_edge_lo=T" (hil-probe watch; loopback: counts only).
rig_watch() {
    case "$STIM" in
    gpio-sim) HIL_FIFO_PRIO=$PROBE_PRIO hil-probe watch "$(sim_attr "$1" value)" "$2" "$PROBE_PERIOD_US" ;;
    loopback)
        eval "off=\${LOOP_$1:?LOOP_$1 not set in the rig config}"
        n=$(timeout "$(( ($2 + 999) / 1000 ))" gpiomon "$LOOP_CHIP" "$off" 2>/dev/null | grep -c EDGE)
        v=$(gpioget "$LOOP_CHIP" "$off")
        echo "samples=0 high=$v edges=$n first_edge=0 last_edge=0 final=$v" ;;
    esac
}
# rig_watch_start LINE MS FILE [AFTER_EDGE_MS]: rig_watch LINE MS into FILE in the background
# (WATCH_PID), and return once the watch has taken its first sample (up to 10 s; status 1 if it
# never did), so a stimulus applied after it is inside the watch however late a busy rig started
# the process. With AFTER_EDGE_MS the watch ends that long after its first edge, and MS is only
# the most it waits for one (a stimulus process can start late too).
# A fixed sleep did not hold: once, under TCG on a loaded machine, the watcher's first sample
# came 1.2 s after it was launched and it saw DRIVE_ENABLE only after it had fallen.
WATCH_PID=
rig_watch_start() {
    ready="$3.ready"
    rm -f "$ready"
    HIL_WATCH_READY=$ready
    HIL_WATCH_AFTER_EDGE_MS=${4:-}
    export HIL_WATCH_READY HIL_WATCH_AFTER_EDGE_MS
    rig_watch "$1" "$2" >"$3" &
    WATCH_PID=$!
    unset HIL_WATCH_READY HIL_WATCH_AFTER_EDGE_MS
    n=0
    while [ ! -e "$ready" ] && [ "$n" -lt 1000 ]; do sleep 0.01; n=$((n + 1)); done
    [ -e "$ready" ]
}
field() { echo "$2" | tr ' ' '\n' | sed -n "s/^$1=//p"; } # field NAME "k=v k=v"
# Edge times on the CAN log's clock: gpio-sim samples do; gpiomon's (loopback) are
# CLOCK_MONOTONIC and only counted, so the tick-bounded GPIO checks need STIM=gpio-sim.
rig_has_edge_times() { [ "$STIM" = gpio-sim ]; }

# ---- the board daemon ----
BOARD_PID=
STAMP_PID=
# Starts argil-board with the rig's GPIO chip (not with --bus sim) plus "$@"; its stderr, each
# line timestamped, goes to $OUT/$CHECK.board.log. Waits (up to 10 s) for "running at".
board_start() {
    log="$OUT/$CHECK.board.log"
    rm -f "$OUT/board.fifo"; mkfifo "$OUT/board.fifo"
    hil-probe stamp <"$OUT/board.fifo" >"$log" &
    STAMP_PID=$!
    chip="--gpio-chip $GPIO_CHIP"
    case " $* " in *" --bus sim "*) chip= ;; esac
    key=; case " $* " in *" udp:"*) [ -n "${ARGIL_LINK_KEY:-}" ] && key="--key $ARGIL_LINK_KEY" ;; esac
    # shellcheck disable=SC2086
    argil-board $chip $BOARD_EXTRA $key "$@" >"$OUT/board.fifo" 2>&1 &
    BOARD_PID=$!
    board_wait "running at" 20 >/dev/null || return 1
}
# Waits up to S seconds for PATTERN in the board log; prints the matching line's timestamp.
board_wait() {
    i=0
    while [ "$i" -lt $(($2 * 20)) ]; do
        t=$(grep -m 1 -- "$1" "$OUT/$CHECK.board.log" 2>/dev/null | cut -d' ' -f1)
        [ -n "$t" ] && { echo "$t"; return 0; }
        kill -0 "$BOARD_PID" 2>/dev/null || { sleep 0.1; break; }
        sleep 0.05; i=$((i + 1))
    done
    t=$(grep -m 1 -- "$1" "$OUT/$CHECK.board.log" 2>/dev/null | cut -d' ' -f1)
    [ -n "$t" ] && { echo "$t"; return 0; }
    return 1
}
board_alive() { [ -n "$BOARD_PID" ] && kill -0 "$BOARD_PID" 2>/dev/null; }
# The board's account of its last host-lost fault ("host lost at tick N: its last frame taken
# in … ms before; the link thread last ran … ms before and last queued a datagram … ms before"),
# for a failure message: whether hil-host fell silent, the link thread was held off, or the
# datagrams reached the link thread and not the loop. Empty when it had none.
board_host_lost() {
    sed -n 's/^[0-9.]* argil-board: \(host lost at tick .*\)$/; board: \1/p' "$OUT/$CHECK.board.log" 2>/dev/null | tail -n 1
}

board_tail() { tail -n "${1:-3}" "$OUT/$CHECK.board.log" 2>/dev/null | cut -d' ' -f2- | tr '\n' '|'; }
# SIGTERM, then the exit status (0 = clean stop with statistics).
board_stop() {
    [ -n "$BOARD_PID" ] || return 0
    kill -TERM "$BOARD_PID" 2>/dev/null
    st=0; wait "$BOARD_PID" || st=$?
    BOARD_PID=
    [ -n "$STAMP_PID" ] && wait "$STAMP_PID" 2>/dev/null
    STAMP_PID=
    return "$st"
}

# ---- CAN ----
CANDUMP_PID=
# The logger runs SCHED_FIFO with a 16 MiB socket buffer (a CAN frame takes about 1 KiB of
# socket memory: 4 MiB held 0.7 s of a scenario's traffic, and a candump that far behind lost
# frames, so SYNC counts and verdicts were wrong, CI 2026-12-02); -d reports any frame the
# socket still drops (DROPCOUNT lines, moved to $CHECK.candump.drops by can_log_stop).
# Returns once candump holds its CAN socket (up to 10 s), so the frames the check causes next
# (a board's NMT start) are in the log however late a busy rig starts it; a fixed sleep was the
# same bet that failed rig_watch once (see rig_watch_start).
can_log_start() {
    hil-probe fifo "$CANDUMP_PRIO" candump -L -d -r 16777216 "$CAN_IF" >"$OUT/$CHECK.candump.log" 2>"$OUT/$CHECK.candump.err" &
    CANDUMP_PID=$!
    cl_n=0
    while ! ls -l "/proc/$CANDUMP_PID/fd" 2>/dev/null | grep -q 'socket:' && [ "$cl_n" -lt 1000 ]; do
        sleep 0.01; cl_n=$((cl_n + 1))
    done
    sleep 0.05 # its bind follows the socket call
}
# candump runs under the rig's real-time work and may be far behind (0.7 s of frames were still
# in its socket when a scenario's log was cut, 2026-12-02): before it is stopped it writes out
# what it holds: while the board ticks, until a frame stamped after now is in the log; once the
# board is gone, until the log stops growing for 0.3 s; at most 10 s. (Its own variable names:
# the checks' are global.)
can_log_stop() {
    [ -n "$CANDUMP_PID" ] || return 0
    cls_t=$(hil-probe now) cls_i=0 cls_size=-1 cls_still=0
    while [ "$cls_i" -lt 100 ] && kill -0 "$CANDUMP_PID" 2>/dev/null; do
        if board_alive; then
            cls_last=$(tail -n 1 "$OUT/$CHECK.candump.log" 2>/dev/null | sed -n 's/^(\([0-9.]*\)).*/\1/p')
            [ -n "$cls_last" ] && awk -v a="$cls_last" -v b="$cls_t" 'BEGIN { exit !(a >= b) }' && break
        else
            cls_now=$(wc -c <"$OUT/$CHECK.candump.log" 2>/dev/null || echo 0)
            if [ "$cls_now" = "$cls_size" ]; then cls_still=$((cls_still + 1)); else cls_still=0; fi
            [ "$cls_still" -ge 3 ] && break
            cls_size=$cls_now
        fi
        sleep 0.1; cls_i=$((cls_i + 1))
    done
    kill "$CANDUMP_PID" 2>/dev/null; wait "$CANDUMP_PID" 2>/dev/null; CANDUMP_PID=
    grep 'DROPCOUNT' "$OUT/$CHECK.candump.log" >"$OUT/$CHECK.candump.drops" 2>/dev/null
    if [ -s "$OUT/$CHECK.candump.drops" ]; then
        grep -v 'DROPCOUNT' "$OUT/$CHECK.candump.log" >"$OUT/$CHECK.candump.tmp"
        mv "$OUT/$CHECK.candump.tmp" "$OUT/$CHECK.candump.log"
    fi
    return 0
}
# Frames with this id#data prefix (e.g. "080#", "000#0101") in the check's CAN log.
can_count() { grep -c " $CAN_IF $1" "$OUT/$CHECK.candump.log"; }
can_first() { grep -m 1 " $CAN_IF $1" "$OUT/$CHECK.candump.log" | sed 's/^(\([0-9.]*\)).*/\1/'; }
can_last() { grep " $CAN_IF $1" "$OUT/$CHECK.candump.log" | tail -n 1 | sed 's/^(\([0-9.]*\)).*/\1/'; }
# SYNC statistics between two times: "n=N rate_hz=R max_gap_ms=G".
sync_stats() {
    awk -v t0="$1" -v t1="$2" -v ifc="$CAN_IF" '
        $2 == ifc && $3 == "080#" { t = substr($1, 2, length($1) - 2) + 0
            if (t < t0 || t > t1) next
            if (n > 0 && t - prev > gap) gap = t - prev
            if (n == 0) first = t
            prev = t; n++ }
        END { rate = (n > 1) ? (n - 1) / (prev - first) : 0
              printf "n=%d rate_hz=%.1f max_gap_ms=%.2f\n", n, rate, gap * 1000 }' "$OUT/$CHECK.candump.log"
}
# Waits up to S seconds for a frame with this id#data prefix in the check's CAN log.
can_wait() {
    i=0
    while [ "$i" -lt $(($2 * 10)) ]; do
        [ "$(can_count "$1")" -ge 1 ] && return 0
        sleep 0.1; i=$((i + 1))
    done
    return 1
}
HB_PIDS=
# Heartbeats from drive nodes 1..3 every 100 ms with NMT state $1 (hex: 00 boot-up, 7F pre-op,
# 05 operational): what three CiA 402 drives would send.
heartbeats_start() {
    for n in 1 2 3; do
        hil-probe fifo $((HOST_PRIO - 1)) cangen "$CAN_IF" -g 100 -I 70$n -L 1 -D "$1" &
        HB_PIDS="$HB_PIDS $!"
    done
}
heartbeats_stop() { [ -n "$HB_PIDS" ] && kill $HB_PIDS 2>/dev/null; for p in $HB_PIDS; do wait "$p" 2>/dev/null; done; HB_PIDS=; }

SIM_PID=
rig_cleanup() {
    host_stop
    [ -n "$SIM_PID" ] && { kill "$SIM_PID" 2>/dev/null; wait "$SIM_PID" 2>/dev/null; SIM_PID=; }
    # A bound gadget is unbound before its daemon goes (the host side sees a disconnect).
    [ -f "$(gadget_dir)/UDC" ] && [ -n "$(cat "$(gadget_dir)/UDC")" ] && echo "" >"$(gadget_dir)/UDC"
    heartbeats_stop
    can_log_stop
    board_stop >/dev/null 2>&1 || true
    [ "$STIM" = gpio-sim ] && [ -d "$GPIO_SIM_CONFIGFS" ] && rig_inputs_released
    return 0
}
# The arm at rest: e-stop released, drives healthy, buttons up.
rig_inputs_released() {
    rig_input "$LINE_ESTOP" 1; rig_input "$LINE_DRIVE_FAULT" 1
    rig_input "$LINE_BTN1" 0; rig_input "$LINE_BTN2" 0
}

# =====================================================================================
# The checks. Arguments come from the plan line.

# kernel [PREEMPT_RT]: which kernel runs; with an argument, `uname -v` must contain it.
check_kernel() {
    v=$(uname -v); r=$(uname -r)
    if [ -n "${1:-}" ] && ! echo "$v" | grep -q -- "$1"; then fail "$r: uname -v '$v' lacks $1"; return; fi
    pass "$r ($v)"
}

# board_lines: argil-board starts on the CAN interface and the GPIO chip and holds every named
# line in the right direction (seen by gpioinfo from outside the daemon).
check_board_lines() {
    t0=$(hil-probe now)
    board_start --can "$CAN_IF" --link "udp:127.0.0.1:$UDP_PORT" || { fail "did not start: $(board_tail)"; return; }
    t1=$(board_wait "running at" 1)
    sleep 0.5
    board_alive || { fail "exited: $(board_tail)"; return; }
    info=$(gpioinfo "$GPIO_CHIP")
    echo "$info" >"$OUT/$CHECK.gpioinfo"
    n_in=0; n_out=0; missing=""
    for l in "$LINE_ESTOP" "$LINE_DRIVE_FAULT" "$LINE_BTN1" "$LINE_BTN2"; do
        echo "$info" | grep "\"$l\"" | grep '"argil-board"' | grep -q ' input ' && n_in=$((n_in + 1)) || missing="$missing $l"
    done
    for l in "$LINE_DRIVE_ENABLE" "$LINE_LED" "$LINE_WDOG"; do
        echo "$info" | grep "\"$l\"" | grep '"argil-board"' | grep -q ' output ' && n_out=$((n_out + 1)) || missing="$missing $l"
    done
    [ -z "$missing" ] || { fail "lines not held as expected:$missing"; return; }
    pass "running in $(ms_between "$t0" "$t1") ms; $n_in inputs + $n_out outputs held by name by argil-board on $GPIO_CHIP, CAN $CAN_IF"
}

# ---- a live host over UDP (hil-host: HELLO, heartbeats, ARM; prints the board's states) ----
HOST_PID=
host_start() { HIL_FIFO_PRIO=$HOST_PRIO hil-host "$UDP_PORT" "$1" >"$OUT/$CHECK.host.log" 2>&1 & HOST_PID=$!; }
host_wait_state() { # STATE S: waits up to S s for the host to report STATE; prints its line
    i=0
    while [ "$i" -lt $(($2 * 20)) ]; do
        l=$(grep -m 1 "state $1\$" "$OUT/$CHECK.host.log" 2>/dev/null) && [ -n "$l" ] && { echo "$l"; return 0; }
        sleep 0.05; i=$((i + 1))
    done
    return 1
}
host_stop() { [ -n "$HOST_PID" ] && kill "$HOST_PID" 2>/dev/null; wait "$HOST_PID" 2>/dev/null; HOST_PID=; }
# Board ticks between two times: SYNC frames in the check's CAN log (one per tick).
ticks_between() { sync_stats "$1" "$2" | sed 's/^n=\([0-9]*\).*/\1/'; }

# can_bus SECONDS: drives announce themselves (boot-up, then pre-operational heartbeats): the
# board sends NMT start to each, then one SYNC per tick (SYNC frames = the daemon's own tick
# count), at the loop rate (counted over SECONDS in the candump log; the rig's TICK_HZ_MIN is
# the floor it must reach), and RPDOs to every operational drive.
check_can_bus() {
    secs=${1:-3}
    can_log_start
    board_start --can "$CAN_IF" --link "udp:127.0.0.1:$UDP_PORT" || { fail "did not start: $(board_tail)"; return; }
    heartbeats_start 7F
    # Pre-operational until the board has answered every node (or 10 s): under a busy
    # emulator the three heartbeat senders can start seconds apart.
    for n in 1 2 3; do can_wait "000#010$n" 10 || break; done
    heartbeats_stop
    heartbeats_start 05
    sleep 0.3
    ta=$(hil-probe now)
    sleep "$secs"
    tb=$(hil-probe now)
    heartbeats_stop
    board_alive || { fail "board exited: $(board_tail)"; return; }
    board_stop; st=$?
    can_log_stop
    [ "$st" = 0 ] || { fail "daemon exit $st after SIGTERM"; return; }
    ticks=$(grep -m 1 'exit: ' "$OUT/$CHECK.board.log" | sed 's/.*exit: \([0-9]*\) ticks.*/\1/')
    syncs=$(can_count "080#")
    nmt=""; for n in 1 2 3; do nmt="$nmt $(can_count "000#010$n")"; done
    rpdo=""; for n in 1 2 3; do rpdo="$rpdo $(can_count "20$n#")"; done
    s=$(sync_stats "$ta" "$tb")
    rate=$(field rate_hz "$s"); gap=$(field max_gap_ms "$s"); n=$(field n "$s")
    for c in $nmt; do [ "$c" -ge 1 ] || { fail "NMT start per node:$nmt (want >= 1 each)"; return; }; done
    for c in $rpdo; do [ "$c" -ge 100 ] || { fail "RPDOs per node:$rpdo (want >= 100)"; return; }; done
    within $((ticks - 2)) "$syncs" "$ticks" || { fail "$syncs SYNC frames for $ticks ticks (want one per tick)"; return; }
    within "$TICK_HZ_MIN" "$rate" 1005 || { fail "SYNC rate $rate Hz over ${secs} s ($n frames), want $TICK_HZ_MIN..1005"; return; }
    pass "NMT start per node:$nmt; $syncs SYNC for $ticks ticks; $rate Hz over ${secs} s (max gap $gap ms); RPDOs per node:$rpdo"
}

# wdog: while healthy (IDLE, no fault) WDOG_KICK toggles every tick; STATUS_LED and
# DRIVE_ENABLE stay low in IDLE.
check_wdog() {
    board_start --can "$CAN_IF" --link "udp:127.0.0.1:$UDP_PORT" || { fail "did not start: $(board_tail)"; return; }
    sleep 0.3
    w=$(rig_watch "$LINE_WDOG" 1000)
    led=$(rig_watch "$LINE_LED" 300)
    en=$(rig_watch "$LINE_DRIVE_ENABLE" 300)
    board_alive || { fail "board exited: $(board_tail)"; return; }
    e=$(field edges "$w"); s=$(field samples "$w")
    # Sampled slower than it toggles: a kicked line changes in a good share of the samples.
    [ "$s" -ge 20 ] && [ $((e * 5)) -ge "$s" ] || { fail "WDOG_KICK: $e edges in 1 s ($s samples), want >= 20 samples and an edge in >= 1 of 5"; return; }
    [ "$(field high "$led")" = 0 ] || { fail "STATUS_LED lit in IDLE: $led"; return; }
    [ "$(field high "$en")" = 0 ] || { fail "DRIVE_ENABLE high in IDLE with no drives: $en"; return; }
    pass "WDOG_KICK $e edges in 1 s ($s samples); STATUS_LED and DRIVE_ENABLE low in IDLE"
}

# estop: a host arms the board (ARMED: DRIVE_ENABLE high); ESTOP_N pulled low -> DRIVE_ENABLE
# low within a tick or two (SYNC frames counted between the pull and the GPIO edge), the host
# sees ESTOP, WDOG_KICK stops, STATUS_LED blinks at 5 Hz of board time (one edge per 100 ticks);
# released -> still ESTOP (latched until the host re-arms).
check_estop() {
    rig_has_edge_times || { skip "needs GPIO edge times on the CAN log's clock (STIM=gpio-sim)"; return; }
    can_log_start
    board_start --can "$CAN_IF" --link "udp:127.0.0.1:$UDP_PORT" || { fail "did not start: $(board_tail)"; return; }
    host_start 8
    host_wait_state ARMED 4 >/dev/null || { fail "host could not arm the board: $(tail -n 2 "$OUT/$CHECK.host.log" | tr '\n' '|')"; return; }
    sleep 0.2
    rig_watch_start "$LINE_DRIVE_ENABLE" 5000 "$OUT/$CHECK.enable" 300 ||
        { fail "the DRIVE_ENABLE watch did not start within 10 s: rig too busy"; return; }
    wp=$WATCH_PID
    sleep 0.4
    if [ "$STIM" = gpio-sim ]; then
        tw=$(hil-probe set "$(sim_attr "$LINE_ESTOP" pull)" pull-down)
    else
        tw="$(hil-probe now) "; rig_input "$LINE_ESTOP" 0; tw="$tw$(hil-probe now)"
    fi
    t_pre=${tw% *}; t0=${tw#* }   # just before and just after the stimulus
    wait "$wp"
    en=$(cat "$OUT/$CHECK.enable")
    t1=$(board_wait "state ESTOP" 2) || { fail "no ESTOP state line: $(board_tail)"; return; }
    hs=$(host_wait_state ESTOP 2) || { fail "host never saw ESTOP"; return; }
    wd=$(rig_watch "$LINE_WDOG" 300)
    led=$(rig_watch "$LINE_LED" 1500)
    rig_input "$LINE_ESTOP" 1
    sleep 0.5
    laststate=$(grep "state " "$OUT/$CHECK.board.log" | tail -n 1 | cut -d' ' -f2-)
    board_alive || { fail "board exited: $(board_tail)"; return; }
    host_stop; board_stop; can_log_stop
    [ "$(field high "$en")" -gt 0 ] && [ "$(field edges "$en")" = 1 ] && [ "$(field final "$en")" = 0 ] ||
        { fail "DRIVE_ENABLE did not go from high to low once: $en"; return; }
    # The fall lies in (lo, hi]: not before the stimulus, and surely late when even the sample
    # before it came more than 2 ticks after the stimulus.
    lo=$(field first_edge_lo "$en"); hi=$(field first_edge "$en")
    # Fallen before the pull: something else dropped it; say what the board went through
    # (in CI on 2026-12-03 and here the same day: "FAULT — host heartbeat lost", the host's
    # heartbeats 51 ticks apart against a timeout of 50: the rig, not the e-stop path).
    within "$t_pre" "$hi" 9e9 || {
        gap=$(sed -n 's/.*max-gap-ms=\([0-9.]*\) max-gap-ticks=\([0-9]*\).*/\1 ms (\2 ticks)/p' "$OUT/$CHECK.host.log")
        fail "DRIVE_ENABLE fell before ESTOP_N was pulled ($en); board: $(grep 'state ' "$OUT/$CHECK.board.log" | cut -d' ' -f3- | tr '\n' ' '); host heartbeats up to ${gap:-?} apart"
        return
    }
    late=$(ticks_between "$t0" "$lo"); ticks=$(ticks_between "$t_pre" "$hi")
    [ "$late" -le 2 ] || { fail "DRIVE_ENABLE fell more than $late ticks after ESTOP_N low, want <= 2"; return; }
    ms="$(ms_between "$t0" "$lo")..$(ms_between "$t_pre" "$hi")"
    [ "$(field edges "$wd")" = 0 ] || { fail "WDOG_KICK still toggling in ESTOP: $wd"; return; }
    le=$(field edges "$led"); lt=$(ticks_between "$(field start "$led")" "$(field end "$led")")
    within $((lt / 100 - 2)) "$le" $((lt / 100 + 2)) || { fail "STATUS_LED $le edges in $lt ticks in ESTOP, want one per 100 ticks (5 Hz)"; return; }
    case "$laststate" in *"state ESTOP"*) ;; *) fail "after release: '$laststate' (want ESTOP latched)"; return ;; esac
    pass "DRIVE_ENABLE fell <= $ticks ticks ($ms ms, GPIO sampling) after ESTOP_N low (host: ${hs#* }, log +$(ms_between "$t0" "$t1") ms); WDOG_KICK stopped; STATUS_LED $le edges in $lt ticks; still ESTOP after release"
}

# drive_heartbeat: three drives send heartbeats, a host arms the board, then the drives fall
# silent: FAULT (drive heartbeat lost) after the 250 ms consumer timeout, i.e. 250 board ticks:
# counted as SYNC frames from the oldest last heartbeat to the DRIVE_ENABLE falling edge. The
# first tick that begins after the heartbeat reads it: the one that ends with the first SYNC
# after it, or the second when the heartbeat came while a tick was computing. The board faults
# when the heartbeat's age passes 250 ticks, in the 251st tick after the one that read it, and
# writes DRIVE_ENABLE after that tick's SYNC: the edge follows SYNC 252 or 253.
check_drive_heartbeat() {
    rig_has_edge_times || { skip "needs GPIO edge times on the CAN log's clock (STIM=gpio-sim)"; return; }
    can_log_start
    board_start --can "$CAN_IF" --link "udp:127.0.0.1:$UDP_PORT" || { fail "did not start: $(board_tail)"; return; }
    heartbeats_start 05
    for n in 1 2 3; do can_wait "70$n#05" 10 || { fail "drive $n's heartbeat sender did not start"; return; }; done
    host_start 8
    host_wait_state ARMED 4 >/dev/null || { fail "host could not arm the board: $(tail -n 2 "$OUT/$CHECK.host.log" | tr '\n' '|')"; return; }
    sleep 0.5
    grep -q "state FAULT" "$OUT/$CHECK.board.log" && { fail "FAULT while heartbeats flow: $(board_tail)"; return; }
    rig_watch_start "$LINE_DRIVE_ENABLE" 8000 "$OUT/$CHECK.enable" 300 ||
        { fail "the DRIVE_ENABLE watch did not start within 10 s: rig too busy"; return; }
    wp=$WATCH_PID
    sleep 0.3
    heartbeats_stop
    wait "$wp"
    t1=$(board_wait "state FAULT" 2) || { fail "no FAULT: $(board_tail)"; return; }
    host_stop; board_stop; can_log_stop
    en=$(cat "$OUT/$CHECK.enable")
    grep -q "state FAULT.*drive heartbeat" "$OUT/$CHECK.board.log" || { fail "FAULT cause: $(board_tail 1)"; return; }
    [ "$(field edges "$en")" = 1 ] && [ "$(field final "$en")" = 0 ] || { fail "DRIVE_ENABLE did not fall once: $en"; return; }
    # The first drive to time out is the one whose last heartbeat is oldest.
    hb=$(for n in 1 2 3; do can_last "70$n#05"; done | sort -n | head -n 1)
    # The fall lies in (lo, hi]: fail when it was surely before SYNC 252 or surely after 253.
    lo=$(field first_edge_lo "$en"); hi=$(field first_edge "$en")
    t_lo=$(ticks_between "$hb" "$lo"); t_hi=$(ticks_between "$hb" "$hi")
    ms="$(ms_between "$hb" "$lo")..$(ms_between "$hb" "$hi")"
    [ "$t_hi" -ge 252 ] && [ "$t_lo" -le 253 ] || { fail "DRIVE_ENABLE fell between $t_lo and $t_hi ticks ($ms ms) after the last heartbeat, want 252..253"; return; }
    pass "FAULT (drive heartbeat lost): DRIVE_ENABLE fell between $t_lo and $t_hi ticks ($ms ms) after the last heartbeat (timeout 250 ms = 250 ticks), logged +$(ms_between "$hb" "$t1") ms"
}

# host_loss: a host arms the board over UDP and is then unplugged (falls silent): FAULT (host
# lost) after the 50 ms host timeout = 50 board ticks (from ARMED there is no force to fade),
# counted as SYNC frames from the sending of the host's last heartbeat to the DRIVE_ENABLE
# falling edge (50..56: the link's delivery adds a few ticks); then
# a new host says HELLO and arms it again without a restart.
check_host_loss() {
    rig_has_edge_times || { skip "needs GPIO edge times on the CAN log's clock (STIM=gpio-sim)"; return; }
    can_log_start
    board_start --can "$CAN_IF" --link "udp:127.0.0.1:$UDP_PORT" || { fail "did not start: $(board_tail)"; return; }
    rig_watch_start "$LINE_DRIVE_ENABLE" 6500 "$OUT/$CHECK.enable" ||
        { fail "the DRIVE_ENABLE watch did not start within 10 s: rig too busy"; return; }
    wp=$WATCH_PID
    sleep 0.5
    host_start 4
    host_wait_state ARMED 4 >/dev/null || { fail "host could not arm the board: $(tail -n 2 "$OUT/$CHECK.host.log" | tr '\n' '|')"; return; }
    wait "$HOST_PID"; HOST_PID=
    wait "$wp"
    t1=$(board_wait "state FAULT" 5) || { fail "no FAULT after the host went: $(board_tail)"; return; }
    en=$(cat "$OUT/$CHECK.enable")
    last=$(grep 'last-heartbeat' "$OUT/$CHECK.host.log" | cut -d' ' -f1)
    gap=$(sed -n 's/.*max-gap-ms=\([0-9.]*\).*/\1/p' "$OUT/$CHECK.host.log")
    mv "$OUT/$CHECK.host.log" "$OUT/$CHECK.host1.log"
    host_start 4
    h2=$(host_wait_state ARMED 4) || { fail "a new host could not re-arm: $(tail -n 2 "$OUT/$CHECK.host.log" | tr '\n' '|')"; return; }
    host_stop; board_stop; can_log_stop
    grep -q "state FAULT.*host" "$OUT/$CHECK.board.log" || { fail "FAULT cause: $(board_tail 1)"; return; }
    [ "$(field high "$en")" -gt 0 ] && [ "$(field final "$en")" = 0 ] && [ "$(field edges "$en")" -ge 1 ] ||
        { fail "DRIVE_ENABLE was not seen high and then falling: $en"; return; }
    lo=$(field last_edge_lo "$en"); hi=$(field last_edge "$en")
    # A host starved long enough looks lost while it still sends: then nothing can be judged.
    within "$last" "$hi" 9e9 || { fail "the board lost the host while it was still sending (longest gap between its heartbeats $gap ms): rig too busy"; return; }
    t_lo=$(ticks_between "$last" "$lo"); t_hi=$(ticks_between "$last" "$hi")
    ms="$(ms_between "$last" "$lo")..$(ms_between "$last" "$hi")"
    # 50 ticks after the board took in the last heartbeat; from its sending add the link's
    # delivery (UDP, link thread, ring: a few ticks under emulation): 50..56.
    [ "$t_hi" -ge 49 ] && [ "$t_lo" -le 56 ] || { fail "DRIVE_ENABLE fell between $t_lo and $t_hi ticks ($ms ms) after the last host heartbeat was sent, want 50..56"; return; }
    pass "host unplugged: FAULT (host lost), DRIVE_ENABLE fell between $t_lo and $t_hi ticks ($ms ms) after its last heartbeat (timeout 50 ms = 50 ticks; heartbeats sent <= $gap ms apart), logged +$(ms_between "$last" "$t1") ms; a new host re-armed it (${h2#* })"
}

# ffs_gadget: argil-board as the USB FunctionFS gadget: descriptors written, UDC bound, the
# device VID:PID appears on the USB host side with a vendor interface and two bulk endpoints;
# unbinding and rebinding the UDC is survived by the daemon.
usb_dev() { # the host-side sysfs device dir of VID:PID, empty if absent
    for d in /sys/bus/usb/devices/*; do
        [ -f "$d/idVendor" ] && [ "$(cat "$d/idVendor")" = "$USB_VID" ] && [ "$(cat "$d/idProduct")" = "$USB_PID" ] && { echo "$d"; return; }
    done
}
usb_wait() { # present|absent, up to 5 s; prints ms waited
    t0=$(hil-probe now); i=0
    while [ $i -lt 100 ]; do
        d=$(usb_dev)
        if [ "$1" = present ] && [ -n "$d" ]; then ms_between "$t0" "$(hil-probe now)"; return 0; fi
        if [ "$1" = absent ] && [ -z "$d" ]; then ms_between "$t0" "$(hil-probe now)"; return 0; fi
        sleep 0.05; i=$((i + 1))
    done
    return 1
}
gadget_dir() { echo /sys/kernel/config/usb_gadget/argil; }
check_ffs_gadget() {
    argil-gadget.sh setup >"$OUT/$CHECK.gadget.log" 2>&1 || { fail "gadget setup: $(tail -n 1 "$OUT/$CHECK.gadget.log")"; return; }
    board_start --can "$CAN_IF" --link "ffs:$FFS_DIR" || { fail "did not start: $(board_tail)"; return; }
    i=0; while [ ! -e "$FFS_DIR/ep1" ] && [ $i -lt 100 ]; do sleep 0.05; i=$((i + 1)); done
    [ -e "$FFS_DIR/ep1" ] || { fail "descriptors not written (no $FFS_DIR/ep1): $(board_tail)"; return; }
    echo "$USB_UDC" >"$(gadget_dir)/UDC" 2>"$OUT/$CHECK.bind.err" || { fail "bind $USB_UDC: $(cat "$OUT/$CHECK.bind.err")"; return; }
    ms1=$(usb_wait present) || { fail "$USB_VID:$USB_PID did not appear on the USB host side"; return; }
    d=$(usb_dev)
    cls=$(cat "$d"/*:1.0/bInterfaceClass 2>/dev/null)
    eps=$(for e in "$d"/*:1.0/ep_*; do echo "$(cat "$e/bEndpointAddress")/$(cat "$e/type")"; done | tr '\n' ' ')
    [ "$cls" = ff ] || { fail "interface class '$cls', want ff (vendor)"; return; }
    nbulk=$(echo "$eps" | grep -o Bulk | wc -l)
    [ "$nbulk" = 2 ] || { fail "endpoints '$eps', want two bulk"; return; }
    echo "" >"$(gadget_dir)/UDC"
    ms2=$(usb_wait absent) || { fail "device still present after unbinding"; return; }
    sleep 0.3
    board_alive || { fail "daemon died on UDC unbind: $(board_tail)"; return; }
    echo "$USB_UDC" >"$(gadget_dir)/UDC" 2>"$OUT/$CHECK.bind.err" || { fail "rebind: $(cat "$OUT/$CHECK.bind.err")"; return; }
    ms3=$(usb_wait present) || { fail "device did not come back after rebinding"; return; }
    sleep 0.3
    board_alive || { fail "daemon died on UDC rebind: $(board_tail)"; return; }
    pass "$USB_VID:$USB_PID on the host side $ms1 ms after binding $USB_UDC (class ff, endpoints ${eps% }); unbind: gone in $ms2 ms, rebind: back in $ms3 ms, daemon alive"
}

# usb_session S: the whole board <-> host USB path in one machine: argil-board (the arm
# in-process, --bus sim) as the FunctionFS gadget, the UDC bound, and the host program
# `argil connect --device usb:VID:PID --arm` on the USB host side through libusb for S seconds:
# the session ends cleanly (exit 0), the board went ACTIVE, and the telemetry CSV has a row for
# (nearly) every board tick of the session.
check_usb_session() {
    secs=${1:-4}
    have argil || { skip "argil (the host program) not built"; return; }
    argil-gadget.sh setup >"$OUT/$CHECK.gadget.log" 2>&1 || { fail "gadget setup: $(tail -n 1 "$OUT/$CHECK.gadget.log")"; return; }
    board_start --bus sim --link "ffs:$FFS_DIR" || { fail "did not start: $(board_tail)"; return; }
    i=0; while [ ! -e "$FFS_DIR/ep1" ] && [ $i -lt 100 ]; do sleep 0.05; i=$((i + 1)); done
    echo "$USB_UDC" >"$(gadget_dir)/UDC" 2>"$OUT/$CHECK.bind.err" || { fail "bind $USB_UDC: $(cat "$OUT/$CHECK.bind.err")"; return; }
    usb_wait present >/dev/null || { fail "$USB_VID:$USB_PID did not appear on the USB host side"; return; }
    st=0
    argil connect --device "usb:$USB_VID:$USB_PID" --seconds "$secs" --arm --out "$OUT/$CHECK.out" \
        --telemetry "$OUT/$CHECK.telemetry.csv" >"$OUT/$CHECK.connect.log" 2>&1 || st=$?
    board_alive || { fail "the daemon died during the USB session: $(board_tail)"; return; }
    [ "$st" = 0 ] || { fail "argil connect exit $st: $(tail -n 2 "$OUT/$CHECK.connect.log" | tr '\n' '|')"; return; }
    grep -q "state ACTIVE" "$OUT/$CHECK.board.log" || { fail "the board never went ACTIVE over USB: $(board_tail)"; return; }
    rows=$(($(grep -c . "$OUT/$CHECK.telemetry.csv") - 1))
    # Telemetry rows against the board's tick span they cover (first and last tick column).
    span=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "tick") c = i; next }
                    c { if (!f) f = $c; l = $c } END { print (c ? l - f + 1 : -1) }' "$OUT/$CHECK.telemetry.csv")
    [ "$rows" -ge 100 ] || { fail "only $rows telemetry rows over USB in $secs s"; return; }
    [ "$span" -lt 0 ] || [ $((rows * 100)) -ge $((span * 95)) ] || { fail "$rows telemetry rows for $span board ticks (> 5 % lost over USB)"; return; }
    pass "argil connect over libusb <-> FunctionFS for $secs s: board ACTIVE, $rows telemetry rows for a span of $span ticks; $(grep -v '^ *$' "$OUT/$CHECK.connect.log" | tail -n 1 | cut -c1-120)"
}

# usb_replug SECS: the cable pulled and put back under a live `argil connect` session of SECS
# seconds: the gadget is unbound from the UDC once connect reports the board ACTIVE (about 1 s
# in; up to SECS-8 s is allowed: under TCG on a loaded machine arming took 5-10 s) and bound
# again 1 s later; the last 7 s leave time to reopen, resynchronise and re-arm. connect must see
# the link lost, reopen the device, resynchronise (the board says HELLO again, the window is
# re-sent) and report the board ACTIVE again for >= 2 s, without a restart of either side.
check_usb_replug() {
    secs=${1:-20}
    have argil || { skip "argil (the host program) not built"; return; }
    argil-gadget.sh setup >"$OUT/$CHECK.gadget.log" 2>&1 || { fail "gadget setup: $(tail -n 1 "$OUT/$CHECK.gadget.log")"; return; }
    board_start --bus sim --link "ffs:$FFS_DIR" || { fail "did not start: $(board_tail)"; return; }
    i=0; while [ ! -e "$FFS_DIR/ep1" ] && [ $i -lt 100 ]; do sleep 0.05; i=$((i + 1)); done
    echo "$USB_UDC" >"$(gadget_dir)/UDC" 2>"$OUT/$CHECK.bind.err" || { fail "bind $USB_UDC: $(cat "$OUT/$CHECK.bind.err")"; return; }
    usb_wait present >/dev/null || { fail "$USB_VID:$USB_PID did not appear on the USB host side"; return; }
    argil connect --device "usb:$USB_VID:$USB_PID" --seconds "$secs" --arm --out "$OUT/$CHECK.out" \
        --telemetry "$OUT/$CHECK.telemetry.csv" >"$OUT/$CHECK.connect.log" 2>&1 &
    cpid=$!
    t0=$(hil-probe now)
    while ! grep -q 'board ACTIVE' "$OUT/$CHECK.connect.log" 2>/dev/null; do
        if ! kill -0 "$cpid" 2>/dev/null; then
            st=0; wait "$cpid" || st=$?
            fail "argil connect exit $st before the unplug: $(tail -n 3 "$OUT/$CHECK.connect.log" | tr '\n' '|')"; return
        fi
        t_unplug=$(awk -v a="$t0" -v b="$(hil-probe now)" 'BEGIN { printf "%.1f", b - a }')
        awk -v t="$t_unplug" -v m="$((secs - 8))" 'BEGIN { exit !(t < m) }' ||
            { kill "$cpid"; fail "the board was not ACTIVE within $((secs - 8)) s, before any unplug: $(tail -n 1 "$OUT/$CHECK.connect.log")"; return; }
        sleep 0.1
    done
    t_unplug=$(awk -v a="$t0" -v b="$(hil-probe now)" 'BEGIN { printf "%.1f", b - a }')
    echo "" >"$(gadget_dir)/UDC" 2>"$OUT/$CHECK.unbind.err" || { kill "$cpid"; fail "unbind: $(cat "$OUT/$CHECK.unbind.err")"; return; }
    gone=$(usb_wait absent) || { kill "$cpid"; fail "the device did not leave the USB host side after unbind"; return; }
    sleep 1
    echo "$USB_UDC" >"$(gadget_dir)/UDC" 2>"$OUT/$CHECK.bind.err" || { kill "$cpid"; fail "rebind: $(cat "$OUT/$CHECK.bind.err")"; return; }
    back=$(usb_wait present) || { kill "$cpid"; fail "the device did not come back after rebind"; return; }
    t_back=$(awk -v a="$t0" -v b="$(hil-probe now)" 'BEGIN { printf "%.1f", b - a }')
    st=0; wait "$cpid" || st=$?
    board_alive || { fail "the daemon died across the replug: $(board_tail)"; return; }
    [ "$st" = 0 ] || { fail "argil connect exit $st: $(tail -n 3 "$OUT/$CHECK.connect.log" | tr '\n' '|')"; return; }
    log="$OUT/$CHECK.connect.log"
    rc=$(sed -n 's/.*reconnects \([0-9]*\),.*/\1/p' "$log" | tail -n 1)
    act=$(sed -n 's/.*ACTIVE entered \([0-9]*\) times.*/\1/p' "$log" | tail -n 1)
    hel=$(sed -n 's/.*board HELLOs \([0-9]*\);.*/\1/p' "$log" | tail -n 1)
    [ "${rc:-0}" -ge 1 ] || { fail "connect saw no reconnect: $(grep 'link  ' "$log" | tail -n 1)"; return; }
    [ "${hel:-0}" -ge 2 ] || { fail "no resynchronisation (board HELLOs ${hel:-0})"; return; }
    [ "${act:-0}" -ge 2 ] || { fail "the board was not ACTIVE again after the replug (ACTIVE entered ${act:-0} times)"; return; }
    # Re-armed and staying so: ACTIVE in at least 2 status lines (1 per second) after the device
    # was back. (Not "ended ACTIVE": under heavy load a VM stall can trip the board's 50 ms
    # host timeout in the last second, which connect re-arms but the session may end first.)
    after=$(awk -v t="$t_back" '$1 == "connect" && $2 + 0 > t + 0 && /link connected  board ACTIVE/ { n++ } END { print n + 0 }' "$log")
    [ "$after" -ge 2 ] || { fail "the board was ACTIVE in $after status lines after the replug (want >= 2): $(grep 'board  ' "$log" | tail -n 1)"; return; }
    pass "unplug $t_unplug s after start, once ACTIVE (device gone after $gone ms) and replug (back after $back ms) under argil connect: reconnects $rc, board HELLOs $hel, ACTIVE entered $act times, ACTIVE in $after status lines (1/s) after the replug"
}

# udp_session MODE: the board over real UDP in the VM with tests/sys/board_udp_client (HELLO,
# window, arm, ACTIVE; host silent -> fade and FAULT; new host -> ACTIVE again). MODE sim:
# argil-board --bus sim (the arm in-process); MODE can: the arm is argil-sim on the CAN bus.
check_udp_session() {
    case "${1:-sim}" in
    sim) board_start --bus sim --link "udp:127.0.0.1:$UDP_PORT" || { fail "did not start: $(board_tail)"; return; } ;;
    can)
        have argil-sim || { skip "argil-sim not built"; return; }
        if [ "$STIM" = gpio-sim ]; then simchip=$(cat "$GPIO_SIM_CONFIGFS/bank0/chip_name"); else simchip=$LOOP_CHIP; fi
        hil-probe fifo $((HOST_PRIO - 1)) argil-sim --can "$CAN_IF" --gpio-chip "$simchip" ${SIM_SUBSTEP_US:+--arm-substep-us "$SIM_SUBSTEP_US"} >"$OUT/$CHECK.sim.log" 2>&1 &
        SIM_PID=$!
        board_start --can "$CAN_IF" --link "udp:127.0.0.1:$UDP_PORT" || { fail "did not start: $(board_tail)"; return; } ;;
    *) fail "udp_session: unknown mode '$1' (sim or can)"; return ;;
    esac
    sleep 0.3
    st=0
    # The host's heartbeats must not wait behind the daemon's FIFO threads (as hil-host), and
    # its host-loss bounds are board ticks with LINK_TICKS for the link each way.
    hil-probe fifo "$HOST_PRIO" board_udp_client "$UDP_PORT" "${LINK_TICKS:-1}" >"$OUT/$CHECK.client.log" 2>&1 || st=$?
    [ "$st" = 0 ] || { fail "client exit $st: $(tail -n 2 "$OUT/$CHECK.client.log" | tr '\n' '|')"; return; }
    pass "$(grep -c . "$OUT/$CHECK.client.log") phases ok: $(tail -n 3 "$OUT/$CHECK.client.log" | tr '\n' '|')"
}

# scenario NAME: hil/scenarios/NAME.scn played on the real buses: argil-sim is the arm (three
# CiA 402 drives on the CAN interface, the e-stop/fault/button lines, DRIVE_ENABLE and WDOG_KICK
# observed) and does the device-side faults; hil-host is the host (peer with tool and windows,
# over UDP) and does the host-side steps (rearm, link faults); both start together. Then
# argil-hil-check decides every expectation from the candump log and argil-sim's event log.
check_scenario() {
    scn="$HIL_DIR/scenarios/$1.scn"
    have argil-sim && have argil-hil-check || { skip "argil-sim/argil-hil-check not built (hook: $scn)"; return; }
    [ -f "$scn" ] || { fail "no scenario file $scn"; return; }
    dur=$(awk '$1 == "duration" { v = $2; if (v ~ /ms$/) { sub("ms", "", v); v /= 1000 } else sub("s", "", v); print int(v + 1.999) }' "$scn")
    can_log_start
    board_start --can "$CAN_IF" --link "udp:127.0.0.1:$UDP_PORT" || { fail "did not start: $(board_tail)"; return; }
    mkdir -p "$OUT/$CHECK.sim"
    # argil-sim's scenario clock counts the board's SYNCs (one 1 ms step each; docs/sim.md): a
    # scenario takes as many board ticks as it names, whatever the emulation speed, so its wall
    # time is only bounded here (20 s per scenario second). The host steps are timed by
    # hil-host's own log below.
    # With --follow it performs each host-side step when argil-sim's event log says argil-sim's
    # clock reached it: one clock for both sides.
    # Scenario time 0 is the board ready to sculpt (docs/sim.md): hil-host writes $CHECK.ready
    # when the board's telemetry says ACTIVE, and argil-sim holds its clock at 0 until then
    # (the drives boot and are enabled meanwhile), at most START_TIMEOUT_S.
    ready="$OUT/$CHECK.ready"
    rm -f "$ready"
    HIL_FIFO_PRIO=$HOST_PRIO hil-host "$UDP_PORT" "$((dur * 20 + START_TIMEOUT_S))" "$scn" --sync "$CAN_IF" \
        --follow "$OUT/$CHECK.sim/events.log" --ready-file "$ready" >"$OUT/$CHECK.host.log" 2>&1 &
    HOST_PID=$!
    st=0
    # argil-sim finds a gpio-sim chip by its device name (gpiochipN); a real rig's arm
    # stand-in drives the board's lines through the loopback chip.
    if [ "$STIM" = gpio-sim ]; then simchip=$(cat "$GPIO_SIM_CONFIGFS/bank0/chip_name"); else simchip=$LOOP_CHIP; fi
    # The arm is its own hardware: it must not wait behind the daemon's SCHED_FIFO loop. It
    # starts at SIM_PRIO, under the board's link thread (its start-up is heavy under TCG and the
    # host's heartbeats must get in), and raises itself to SIM_RUN_PRIO (--run-prio) before it
    # answers the first SYNC: above the rig's host and the board's link thread, or it fell up
    # to 90 board ticks behind the SYNCs it answers and the drives' heartbeats reached the board
    # up to 90 ticks late (raised only at the scenario's start, under load it starved while the
    # drives booted and the board faulted "drive heartbeat lost" before time 0).
    # SIM_CPU pins it to the CPU the board's loop does not own (the VM's vCPU 1).
    ${SIM_CPU:+taskset -c "$SIM_CPU"} hil-probe fifo "$SIM_PRIO" argil-sim --can "${SIM_CAN_IF:-$CAN_IF}" --gpio-chip "$simchip" --scenario "$scn" --log-dir "$OUT/$CHECK.sim" \
        --start-when "$ready" --start-timeout "$START_TIMEOUT_S" ${SIM_RUN_PRIO:+--run-prio "$SIM_RUN_PRIO"} \
        ${SIM_SUBSTEP_US:+--arm-substep-us "$SIM_SUBSTEP_US"} \
        >"$OUT/$CHECK.sim.out" 2>&1 &
    SIM_PID=$!
    wait "$SIM_PID" || st=$?; SIM_PID=
    # An arm stand-in that gave up (the board never got ready) ends the check: hil-host would
    # run out its whole budget (20 s per scenario second + START_TIMEOUT_S) for nothing, and in
    # CI on 2026-12-03 three such waits of 170-220 s each ran the VM past its time limit.
    [ "$st" = 0 ] || kill "$HOST_PID" 2>/dev/null
    hst=0; wait "$HOST_PID" || hst=$?; HOST_PID=
    can_log_stop
    if [ "$st" != 0 ]; then
        # what the board went through, as hil-host saw it ("tick=714 state IDLE|…")
        hstates=$(sed -n 's/^[0-9.]* \(tick=[0-9]* state [A-Z_]*\)$/\1/p; s/^[0-9.]* \(tick=[0-9]* ready\):.*/\1/p' "$OUT/$CHECK.host.log" | tail -n 4 | tr '\n' '|')
        fail "argil-sim exit $st: $(tail -n 2 "$OUT/$CHECK.sim.out" | tr '\n' '|') [host saw: ${hstates:-no telemetry}$(board_host_lost)]"
        return
    fi
    [ "$hst" = 0 ] || [ "$hst" = 3 ] || { fail "hil-host exit $hst: $(tail -n 2 "$OUT/$CHECK.host.log" | tr '\n' '|')"; return; }
    # A CAN log with holes cannot be judged (ticks are counted in it): say so, not a verdict.
    if [ -s "$OUT/$CHECK.candump.drops" ]; then
        fail "the CAN log lost frames, nothing can be judged: $(tail -n 1 "$OUT/$CHECK.candump.drops")"
        return
    fi
    cst=0
    # Frames from several senders on vcan can carry timestamps a few 100 us out of order; the
    # checker wants time order: give it a stably sorted copy, keep the raw log.
    sort -s -k1,1 "$OUT/$CHECK.candump.log" >"$OUT/$CHECK.candump.sorted.log"
    # A host-side step happened when hil-host performed it: its "T step line=N …" lines join
    # argil-sim's event log as injections (argil-sim's own "host line=N" lines are only notes).
    { cat "$OUT/$CHECK.sim/events.log"
      awk '$2 == "step" && $NF != "unsupported" { $1 = "(" $1 ")"; $2 = "inject"; print }' "$OUT/$CHECK.host.log"
    } | sort -s -k1,1 >"$OUT/$CHECK.events.log"
    # A host-side step counts from hil-host's sending; the board sees it after the link's
    # delivery (UDP, its link thread, the ring): LINK_TICKS of the rig config, as host_loss's
    # 50..56 ticks.
    argil-hil-check --link-ticks "${LINK_TICKS:-1}" "$scn" "$OUT/$CHECK.candump.sorted.log" \
        "$OUT/$CHECK.events.log" >"$OUT/$CHECK.check.log" 2>&1 || cst=$?
    res=$(tail -n 1 "$OUT/$CHECK.check.log")
    bad=$(grep -v '^ok\|^PASS\|passed, ' "$OUT/$CHECK.check.log" | head -n 2 | tr '\n' '|')
    if [ "$hst" = 3 ]; then
        skip "host-side step(s) hil-host cannot play over UDP: $(grep -o 'step line=[0-9]* .* unsupported' "$OUT/$CHECK.host.log" | tr '\n' '|'); checker: $res"
        return
    fi
    # How long the board took to get ready, and how long the arm stand-in ran behind the board
    # without catching up (SYNCs read before its socket first ran empty): the figures to look at
    # when a bound is near.
    # catch_up_ms: from argil-sim seeing the ready file to its start (its socket read empty).
    pre=$(sed -n 's/.* start scenario .*preroll_syncs=\([0-9]*\) preroll_ms=\([0-9]*\) catch_up_ms=\([0-9.]*\).*/ready after \1 board ticks (\2 ms), started \3 ms after/p' "$OUT/$CHECK.sim/events.log" | head -n 1)
    lag=$(sed -n 's/.* end .*max_backlog_syncs=\([0-9]*\).*/, arm stand-in behind for up to \1 ticks before catching up/p' "$OUT/$CHECK.sim/events.log" | head -n 1)
    # How late the bus delivered a frame: in the raw log (delivery order) the most a frame's
    # stamp lies behind the latest stamp before it (vcan0's frames wait in the sender CPU's
    # backlog until the network softirq runs; see vm/init).
    # How long the rig held hil-host's real-time thread back at worst once its heartbeats were
    # due (the board seen), and its first turn (the SYNCs queued since its socket opened).
    hgap=$(sed -n 's/.* rt_max_gap_ms=\([0-9.]*\) rt_max_gap_at_s=\([0-9.]*\) rt_first_turn_ms=\([0-9.]*\).*/, host thread held up to \1 ms (at +\2 s; first turn \3 ms)/p' "$OUT/$CHECK.host.log" | tail -n 1)
    late=$(awk '{ t = substr($1, 2, length($1) - 2) + 0; if (t > m) m = t; else if (m - t > d) d = m - t }
                END { printf ", frames delivered up to %.1f ms late", d * 1000 }' "$OUT/$CHECK.candump.log")
    # The board's states as it logged them, for a failure: "ACTIVE FAULT(drive heartbeat lost)".
    states=$(sed -n 's/^[0-9.]* argil-board: state \([A-Z]*\)\( — \(.*\)\)*$/\1(\3)/p' "$OUT/$CHECK.board.log" | sed 's/()//' | tr '\n' ' ')
    # and its last word (a daemon that gave up says why: "CAN bus-off not recovered ...").
    last=$(tail -n 1 "$OUT/$CHECK.board.log" | cut -d' ' -f2-)
    [ "$cst" = 0 ] || { fail "$res: $bad [$pre$lag$late$hgap; board: $states; last: $last$(board_host_lost)]"; return; }
    # A stranger on the network (`stranger KIND for D`): the board refused its frames by reason,
    # as its RT_STATS told hil-host, and served one host session throughout.
    if grep -q '^at .* stranger ' "$scn"; then
        sl=$(grep ' stranger replayed_other=' "$OUT/$CHECK.host.log" | tail -n 1)
        [ -n "$sl" ] || { fail "$res, but hil-host reported no stranger line"; return; }
        ws=$(echo "$sl" | sed -n 's/.* wrong_source=\([0-9]*\).*/\1/p')
        dup=$(echo "$sl" | sed -n 's/.* duplicate=\([0-9]*\) stale=\([0-9]*\).*/\1 + \2/p')
        ses=$(echo "$sl" | sed -n 's/.* sessions=\([0-9]*\).*/\1/p')
        mac=$(echo "$sl" | sed -n 's/.* bad_mac=\([0-9]*\).*/\1/p')
        keyed=$(echo "$sl" | sed -n 's/.* keyed=\([01]\).*/\1/p')
        dup=$((${dup:-0}))
        # Keyed, a tag is checked first: forged and junk datagrams are bad tags; the captured
        # ones verify and are refused for their sender (another address) or as replays (the
        # host's own). Unkeyed, only the sender and the sequence window stand in the way.
        [ "${ws:-0}" -gt 0 ] && [ "$dup" -gt 0 ] && [ "${ses:-0}" = 1 ] &&
            { [ "${keyed:-0}" = 0 ] || [ "${mac:-0}" -gt 0 ]; } ||
            { fail "$res, but the board's refusals do not show the stranger: $(echo "$sl" | cut -d' ' -f2-)"; return; }
        res="$res; stranger refused: wrong source $ws, replayed $dup, bad tag ${mac:-0}, one session"
    fi
    pass "$res ($(grep -c . "$OUT/$CHECK.candump.log") CAN frames logged; $pre$lag$late$hgap)"
}

# can_controller NAME: scenario NAME on real CAN controller drivers instead of vcan, as a user
# with a CAN card runs it (hil/README.md): argil-board on can0 and argil-sim on can1, two SJA1000
# controllers (qemu's kvaser_pci, the kernel's sja1000 driver) on one emulated bus at 1 Mbit/s,
# with frames acknowledged, error counters and bus states. Afterwards both controllers must
# still be ERROR-ACTIVE with no bus errors counted.
check_can_controller() {
    for c in can0 can1; do
        [ -d "/sys/class/net/$c" ] || { skip "no CAN controller $c (qemu -device kvaser_pci)"; return; }
    done
    saved_if=$CAN_IF
    CAN_IF=can0 SIM_CAN_IF=can1
    check_scenario "$1"
    CAN_IF=$saved_if SIM_CAN_IF=
    hw=""
    for c in can0 can1; do
        ip-full -details -statistics link show "$c" >"$OUT/$CHECK.$c.link" 2>&1
        # "can state ERROR-ACTIVE (berr-counter tx 0 rx 0) restart-ms 0"
        st=$(grep -o 'can state [A-Z-]*' "$OUT/$CHECK.$c.link" | sed 's/can state //')
        case "$st" in ERROR-ACTIVE) ;; *) fail "$c ended in state '${st:-?}' (see $CHECK.$c.link)"; return ;; esac
        hw="$hw $c $st"
    done
    [ "$RESULT" = PASS ] && DETAIL="$DETAIL; controllers:$hw"
}

