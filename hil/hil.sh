#!/bin/sh
# make hil: Debian's kernel debs (cached) -> vmlinux, modules, gpio-sim.ko -> one initramfs per
# kernel flavour -> boot each under qemu-system-x86_64 -accel tcg and run the plan lines of that
# rig (hil/plan.txt: std = Debian's amd64 kernel, rt = the PREEMPT_RT kernel) -> one summary.
# Usage: hil/hil.sh BUILD_DIR [std|rt|scn ...]  (the argil binaries come from BUILD_DIR/rel)
#   Rigs (default "std rt", or $HIL_RIGS): std and rt boot Debian's amd64 and PREEMPT_RT kernels
#   and run the plan lines tagged so; scn boots the amd64 kernel for the argil-sim scenario lines.
# Logs: BUILD_DIR/hil/run-<rig>/console.log (the VM's serial console) and run-<rig>/logs/ (per
# check: the daemon's timestamped stderr, the candump -L log, GPIO samples, host output).
# Env: HIL_CACHE (the debs; default /var/cache/argil-hil as root, else BUILD_DIR/hil/debs),
#      HIL_TIMEOUT_S (per boot, default 900), HIL_MEM_MB (default 256), HIL_SMP (default 2:
#      argil-board's loop on vCPU 0, the rig's arm (argil-sim), host and candump on vCPU 1; on
#      one vCPU under TCG they starve each other and the scenarios see "host lost"/"drive
#      heartbeat lost" before sculpting. The bounds are in board ticks, so the two vCPUs
#      stalling independently does not matter).
#      HIL_QEMU_ARGS: more qemu options, e.g. "-icount shift=0,sleep=off" with HIL_SMP=1
#      (instruction-counted guest time, independent of the host's load; qemu 7.2 hangs
#      bringing up a second vCPU under -icount).
# Besides vcan0 the VM has two emulated Kvaser PCIcan (SJA1000) controllers on one emulated CAN
# bus: can0 and can1 with the kernel's real controller drivers (check can_controller).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
build=${1:?usage: hil/hil.sh BUILD_DIR [std|rt ...]}
shift
rigs=${*:-${HIL_RIGS:-std rt}}
mkdir -p "$build/hil"
b=$(cd "$build/hil" && pwd)
rel=$(cd "$build/rel" && pwd)
say() { echo "hil: $*"; }
t_start=$(date +%s.%N)
since() { awk -v a="$t_start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f s", b - a }'; }

# What each rig will run, before anything can fail: tests/sys/test_hil.sh counts a planned check
# that never reports (a VM that died, a kernel that did not build) as failed.
for rig in $rigs; do
    say "rig '$rig' plans $(awk -v r="$rig" '$1 == r || $1 == "*" { n++ } END { print n + 0 }' \
        "${HIL_PLAN:-$here/plan.txt}") checks"
done

if [ -z "${HIL_CACHE:-}" ]; then
    if [ "$(id -u)" = 0 ]; then HIL_CACHE=/var/cache/argil-hil; else HIL_CACHE=$b/debs; fi
fi
abi=$(sh "$here/fetch-debs.sh" "$HIL_CACHE" | tail -n 1)
say "debs ready ($(since))"
sh "$here/build-kernel.sh" "$HIL_CACHE" "$abi" "$b"
say "kernels ready ($(since))"

total_p=0 total_f=0 total_s=0 summary="" bad=""
for rig in $rigs; do
    case "$rig" in
    std|scn) kv=$abi-amd64 ;;
    rt) kv=$abi-rt-amd64 ;;
    *) say "unknown rig '$rig' (std, rt or scn)"; exit 2 ;;
    esac
    img="$b/initramfs-$kv.cpio.gz"
    sh "$here/mkinitramfs.sh" "$b/$kv" "$b/kroot" "$rel" "$img"
    run="$b/run-$rig"
    rm -rf "$run" && mkdir -p "$run/logs"
    say "booting $kv (rig '$rig') under qemu -accel tcg; console: $run/console.log"
    t0=$(date +%s.%N)
    st=0
    # The VM prints one line per check; show those as they come, keep the whole console.
    { timeout "${HIL_TIMEOUT_S:-900}" qemu-system-x86_64 -accel tcg -M q35 -smp "${HIL_SMP:-2}" \
        -m "${HIL_MEM_MB:-256}" -nodefaults -nographic -no-reboot -net none -serial stdio \
        -device isa-debug-exit,iobase=0xf4,iosize=0x04 \
        -object can-bus,id=canbus0 -device kvaser_pci,canbus=canbus0 -device kvaser_pci,canbus=canbus0 \
        ${HIL_QEMU_ARGS:-} -kernel "$b/$kv/vmlinux" -initrd "$img" \
        -append "console=ttyS0 quiet loglevel=3 panic=-1 noirqdebug argil.rig=$rig" </dev/null 2>&1 || st=$?
      echo "HIL-QEMU-STATUS $st"; } | tr -d '\r' | tee "$run/console.log" |
        grep --line-buffered -E '^(PASS|FAIL|SKIP|HIL-INIT|[0-9]+ passed)' | sed -u "s/^/  [$rig] /"
    st=$(sed -n 's/^HIL-QEMU-STATUS //p' "$run/console.log")
    secs=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
    sed -n '/^HIL-LOGS-BEGIN$/,/^HIL-LOGS-END$/p' "$run/console.log" | sed '1d;$d' |
        base64 -d 2>/dev/null | tar -xzf - -C "$run/logs" 2>/dev/null || say "no logs came out of the VM"
    line=$(grep -E '^[0-9]+ passed, [0-9]+ failed' "$run/console.log" | tail -n 1)
    if [ -z "$line" ]; then
        say "rig '$rig': no summary from the VM (qemu status $st after $secs s); last lines:"
        tail -n 15 "$run/console.log" | sed 's/^/    /'
        total_f=$((total_f + 1)); bad="$bad $rig"
        continue
    fi
    p=$(echo "$line" | sed 's/^\([0-9]*\) passed.*/\1/')
    f=$(echo "$line" | sed 's/^[0-9]* passed, \([0-9]*\) failed.*/\1/')
    s=$(echo "$line" | sed -n 's/.*failed, \([0-9]*\) skipped.*/\1/p'); s=${s:-0}
    # qemu's status must agree: 0 = poweroff (all passed), 3 = isa-debug-exit (a failure).
    if { [ "$f" = 0 ] && [ "$st" != 0 ]; } || { [ "$f" != 0 ] && [ "$st" != 3 ]; }; then
        say "rig '$rig': qemu exit status $st does not match '$line'"
        f=$((f + 1))
    fi
    total_p=$((total_p + p)); total_f=$((total_f + f)); total_s=$((total_s + s))
    [ "$f" = 0 ] || bad="$bad $rig"
    boot=$(sed -n 's/^.*HIL-INIT: kernel .* up after \([0-9.]*\) s.*/\1/p' "$run/console.log")
    summary="$summary; $rig: $p passed, $f failed, $s skipped in $secs s (init after ${boot:-?} s)"
done
say "total $(since)${summary}"
[ -z "$bad" ] || say "failed rig(s):$bad — see $b/run-<rig>/console.log and logs/"
echo "$total_p passed, $total_f failed, $total_s skipped"
[ "$total_f" = 0 ]
