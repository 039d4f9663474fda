#!/bin/sh
# The layer check must catch what it is there for: a host/ file that includes a firmware
# header fails, naming the file and line; a known crossing that is gone fails too; the real
# tree passes.
set -u
. tests/lib/report.sh
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
report_plan 7

mkdir -p "$tmp/tree/host/app" "$tmp/tree/firmware/core" "$tmp/tree/shared" "$tmp/tree/toolchain"
printf '#pragma once\n' >"$tmp/tree/shared/units.h"
printf '#pragma once\n#include "shared/units.h"\n' >"$tmp/tree/firmware/core/safety.h"
printf '#include "shared/units.h"\nint main(void) { return 0; }\n' >"$tmp/tree/host/app/main.c"
if sh toolchain/check-layers.sh "$tmp/tree" >"$tmp/clean" 2>&1; then
    report PASS clean_tree_passes
else
    report FAIL clean_tree_passes "$(tail -n 3 "$tmp/clean")"
fi

printf '#include "shared/units.h"\n#include "firmware/core/safety.h"\nint main(void) { return 0; }\n' \
    >"$tmp/tree/host/app/main.c"
if sh toolchain/check-layers.sh "$tmp/tree" >"$tmp/planted" 2>&1; then
    report FAIL planted_crossing_fails "host/app/main.c includes firmware/core/safety.h and the check passed"
else
    report PASS planted_crossing_fails
fi
if grep -q '^host/app/main.c:2: includes "firmware/core/safety.h": host/' "$tmp/planted"; then
    report PASS planted_crossing_named
else
    report FAIL planted_crossing_named "no host/app/main.c:2 line in: $(head -n 3 "$tmp/planted")"
fi

# bus/ (SocketCAN, libgpiod) serves the board's HAL and argil-sim, never the host.
mkdir -p "$tmp/tree/bus" "$tmp/tree/sim/app"
printf '#pragma once\n#include "shared/units.h"\n' >"$tmp/tree/bus/can_socket.h"
printf '#include "bus/can_socket.h"\nint main(void) { return 0; }\n' >"$tmp/tree/sim/app/argil_sim_main.c"
printf '#include "bus/can_socket.h"\nint main(void) { return 0; }\n' >"$tmp/tree/host/app/main.c"
if sh toolchain/check-layers.sh "$tmp/tree" >"$tmp/bus" 2>&1; then
    report FAIL host_includes_no_bus "host/app/main.c includes bus/can_socket.h and the check passed"
else
    report PASS host_includes_no_bus
fi
printf '#include "shared/units.h"\nint main(void) { return 0; }\n' >"$tmp/tree/host/app/main.c"
if sh toolchain/check-layers.sh "$tmp/tree" >"$tmp/sim_bus" 2>&1; then
    report PASS sim_app_may_include_bus
else
    report FAIL sim_app_may_include_bus "$(tail -n 3 "$tmp/sim_bus")"
fi

printf 'host/app/main.c shared/units.h\n' >"$tmp/tree/toolchain/layers-known.txt"
if sh toolchain/check-layers.sh "$tmp/tree" >"$tmp/stale" 2>&1; then
    report FAIL stale_known_entry_fails "an entry that crosses nothing was accepted"
else
    report PASS stale_known_entry_fails
fi

if sh toolchain/check-layers.sh . >"$tmp/real" 2>&1; then
    report PASS real_tree_passes "$(tail -n 1 "$tmp/real")"
else
    report FAIL real_tree_passes "$(grep -v '^check-layers: known' "$tmp/real" | head -n 5)"
fi
