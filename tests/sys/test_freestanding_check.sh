#!/bin/sh
# The freestanding check must catch what it is there for: an object of the real-time code
# that reaches malloc, printf or a blocking call fails the build.
set -eu
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
for call in 'return malloc(4);' 'free(q); return 0;' 'printf("x"); return 0;' 'usleep(10); return 0;' 'return fopen("x", "r");'; do
    printf '#define _DEFAULT_SOURCE\n#include <stdlib.h>\n#include <stdio.h>\n#include <unistd.h>\nvoid *bad(void *q);\nvoid *bad(void *q) { (void)q; %s }\n' "$call" >"$tmp/bad.c"
    cc -c -O2 "$tmp/bad.c" -o "$tmp/bad.o"
    if sh toolchain/check-freestanding.sh "$tmp/bad.o" >"$tmp/out" 2>&1; then
        fail "check-freestanding accepted: $call"
    fi
    grep -q 'must not call' "$tmp/out" || fail "no clear message for: $call"
done
# And it accepts the real core + shared objects: those of today's sources, not a stale object
# of a file since moved or removed.
objs=$(for c in shared/*.c firmware/core/*.c; do echo "$REL/${c%.c}.o"; done)
sh toolchain/check-freestanding.sh $objs || fail "the real-time objects are not freestanding"
echo "freestanding check: catches heap, stdio and blocking calls; core + shared pass"
