#!/bin/sh
# Proves the tree keeps DESIGN.md's layers: every #include "..." in a C source or header is
# resolved (the including file's folder first, then the tree's root, as -I. does) and checked
# against the table below. Fails naming file:line and the rule broken.
# Usage: toolchain/check-layers.sh [ROOT]   (default: the current folder)
# ROOT/toolchain/layers-known.txt, if present, lists crossings not yet removed ("FILE INCLUDED"
# per line, # comments): they are printed, not failed; an entry that no longer occurs fails,
# so the list only shrinks.
#
# layer of a file         may include
#   shared/               shared/
#   firmware/core/        firmware/core/, shared/, and the HAL interface firmware/hal/hal.h
#   bus/                  bus/, shared/  (hosted Linux access to a real CAN bus and GPIO chip)
#   firmware/hal/         firmware/hal/, bus/, shared/  (the sim backends hal_sim.*, hal_sim_bus.*
#                         also sim/)
#   firmware/board/,      firmware/core/, firmware/hal/, bus/, shared/  (the daemon's and the MCU
#   firmware/cortexm/     image's mains compose the core and a HAL)
#   sim/rig/              firmware/, sim/, shared/, host/link/link.h
#   sim/app/              sim/ (not sim/rig/), bus/, shared/  (argil-sim plays the drives on a
#                         real bus)
#   sim/                  sim/ (not sim/rig/), shared/
#   host/                 host/, shared/, sim/rig/rig.h
#   hil/, tests/          anything
set -eu
root=${1:-.}
known="$root/toolchain/layers-known.txt"
[ -f "$known" ] || known=/dev/null
cd "$root"
files=$(find shared bus firmware sim host hil tests -type f \( -name '*.c' -o -name '*.h' \) 2>/dev/null | LC_ALL=C sort)
[ -n "$files" ] || { echo "check-layers: no C sources under $root" >&2; exit 1; }
# shellcheck disable=SC2086
awk -v known="$known" '
function layer(p) {
    if (p ~ /^shared\//) return "shared"
    if (p ~ /^bus\//) return "bus"
    if (p ~ /^firmware\/core\//) return "core"
    if (p ~ /^firmware\/hal\/hal_sim(_bus)?\.[ch]$/) return "hal_sim"
    if (p ~ /^firmware\/hal\//) return "hal"
    if (p ~ /^firmware\/(board|cortexm)\//) return "main"
    if (p ~ /^sim\/rig\//) return "rig"
    if (p ~ /^sim\/app\//) return "sim_app"
    if (p ~ /^sim\//) return "sim"
    if (p ~ /^host\//) return "host"
    if (p ~ /^(hil|tests)\//) return "any"
    return "other"
}
# The rule a file of layer l breaks by including path p, or "" when p is allowed.
function broken(l, p,    t) {
    t = layer(p)
    if (l == "any" || l == "other" || t == "other") return ""
    if (l == "shared") return t == "shared" ? "" : "shared/ includes only shared/"
    if (l == "bus") return (t == "bus" || t == "shared") ? "" : "bus/ includes only bus/ and shared/"
    if (l == "core") return (t == "core" || t == "shared" || p == "firmware/hal/hal.h") ? "" : \
        "firmware/core includes only firmware/core, shared/ and firmware/hal/hal.h"
    if (l == "hal") return (t == "hal" || t == "hal_sim" || t == "bus" || t == "shared") ? "" : \
        "firmware/hal includes only firmware/hal, bus/ and shared/ (sim/ only from hal_sim.*, hal_sim_bus.*)"
    if (l == "hal_sim") return (t == "hal" || t == "hal_sim" || t == "shared" || t == "sim") ? "" : \
        "the sim HAL includes only firmware/hal, sim/ and shared/"
    if (l == "main") return (t ~ /^(core|hal|hal_sim|bus|shared|main)$/) ? "" : \
        "a firmware main composes only firmware/, bus/ and shared/"
    if (l == "rig") return (t ~ /^(core|hal|hal_sim|main|sim|rig|shared)$/ || p == "host/link/link.h") ? "" : \
        "sim/rig includes only firmware/, sim/, shared/ and host/link/link.h"
    if (l == "sim_app") return (t == "sim" || t == "sim_app" || t == "bus" || t == "shared") ? "" : \
        "sim/app includes only sim/ (not sim/rig), bus/ and shared/"
    if (l == "sim") return (t == "sim" || t == "shared") ? "" : "sim/ includes only sim/ and shared/"
    if (l == "host") return (t == "host" || t == "shared" || p == "sim/rig/rig.h") ? "" : \
        "host/ includes only host/, shared/ and sim/rig/rig.h"
    return ""
}
function exists(p,    s, r) {
    r = (getline s < p)
    if (r >= 0) close(p)
    return r >= 0
}
BEGIN {
    while ((getline line < known) > 0) {
        sub(/#.*/, "", line)
        if (split(line, f, " ") == 2) { allow[f[1] " " f[2]] = 1; nallow++ }
    }
}
/^[ \t]*#[ \t]*include[ \t]*"/ {
    inc = $0
    sub(/^[^"]*"/, "", inc)
    sub(/".*/, "", inc)
    dir = FILENAME
    sub(/[^\/]*$/, "", dir)
    path = exists(dir inc) ? dir inc : inc
    while (sub(/[^\/]+\/\.\.\//, "", path)) {}
    why = broken(layer(FILENAME), path)
    if (why == "") next
    if ((FILENAME " " path) in allow) {
        seen[FILENAME " " path] = 1
        printf "check-layers: known: %s:%d: includes %s (%s)\n", FILENAME, FNR, path, why
        next
    }
    printf "%s:%d: includes \"%s\": %s\n", FILENAME, FNR, path, why > "/dev/stderr"
    bad++
}
END {
    for (k in allow) if (!(k in seen)) {
        printf "check-layers: %s no longer crosses a layer: remove it from toolchain/layers-known.txt\n", k > "/dev/stderr"
        bad++
    }
    if (bad) {
        printf "check-layers: %d include(s) break the layers of DESIGN.md (\"Layers\")\n", bad > "/dev/stderr"
        exit 1
    }
    printf "check-layers: includes keep the layers (%d known crossings left)\n", nallow + 0
}' $files
