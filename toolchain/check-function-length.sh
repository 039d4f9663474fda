#!/bin/sh
# Keeps every function in host/ short enough to read in one sitting (CONVENTIONS.md): fails
# naming file:line, the function and its length when one runs over the limit. A function is
# counted from the column-0 line that names it to its closing brace at column 0 (the tree's
# style: the opening brace of a body alone on its line).
# Usage: toolchain/check-function-length.sh [ROOT [MAX_LINES]]   (default: ., 150)
set -eu
root=${1:-.}
max=${2:-150}
cd "$root"
files=$(find host -type f -name '*.c' 2>/dev/null | LC_ALL=C sort)
[ -n "$files" ] || { echo "check-function-length: no C sources under $root/host" >&2; exit 1; }
# shellcheck disable=SC2086
awk -v max="$max" '
FNR == 1 { sig = 0; body = 0 }
# a signature starts at column 0 with a name and "(", and is not a declaration
!body && /^[A-Za-z_]/ && /\(/ && !/;[ \t]*$/ { sig = FNR; line = $0 }
!body && /^\{/ && sig { body = 1; start = sig; head = line }
body && /^\}/ {
    n = FNR - start + 1
    if (n > max) {
        name = head; sub(/\(.*/, "", name); sub(/.*[ \t*]/, "", name)
        printf "check-function-length: %s:%d: %s is %d lines (at most %d)\n", FILENAME, start, name, n, max
        bad++
    }
    body = 0; sig = 0
}
END {
    if (bad) { printf "check-function-length: %d function(s) over %d lines in host/: split them by what they do\n", bad, max; exit 1 }
    printf "check-function-length: every function in host/ is at most %d lines\n", max
}' $files
