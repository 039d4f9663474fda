#!/bin/sh
# Proves the real-time code (firmware/core, shared/) is freestanding: links the given objects
# into one relocatable object and fails if it needs anything beyond a short list of
# allocation-free, non-blocking libc/libm functions, and the HAL interface (firmware/hal/hal.h).
set -eu
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ld -r -o "$tmp/rt.o" "$@"
nm -u "$tmp/rt.o" | awk '{print $2}' | sort -u > "$tmp/undef"
allowed='^(hal_[a-z_]+|memcpy|memset|memmove|memcmp|strlen|sqrtf|fabsf|floorf|ceilf|expf|logf|sinf|cosf|atan2f|acosf|asinf|fminf|fmaxf|powf|roundf|lrintf|__stack_chk_fail|__stack_chk_guard)$'
bad=$(grep -Ev "$allowed" "$tmp/undef" || true)
if [ -n "$bad" ]; then
    echo "check-freestanding: firmware/core and shared/ must not call these (heap, stdio, blocking or unvetted libc):" >&2
    echo "$bad" | sed 's/^/    /' >&2
    exit 1
fi
echo "check-freestanding: core + shared need only: $(tr '\n' ' ' < "$tmp/undef")"
