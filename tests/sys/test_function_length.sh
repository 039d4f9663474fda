#!/bin/sh
# The function-length check must catch what it is there for: a host/ function one line over the
# limit fails, naming file, line, function and length; one at the limit, a declaration and a
# multi-line signature are read right; the real tree passes.
set -u
. tests/lib/report.sh
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
report_plan 4

mkdir -p "$tmp/tree/host/app"
# body_of NAME LINES: a function of exactly LINES lines (signature over two lines, body, braces)
body_of() {
    printf 'static int %s(int a,\n    int b);\n' "$1"
    printf 'static int %s(int a,\n                int b)\n{\n' "$1"
    i=4
    while [ "$i" -lt "$2" ]; do printf '    a += b;\n'; i=$((i + 1)); done
    printf '}\n'
}
{ body_of at_limit 150; body_of short 12; } >"$tmp/tree/host/app/f.c"
if sh toolchain/check-function-length.sh "$tmp/tree" >"$tmp/clean" 2>&1; then
    report PASS at_limit_passes
else
    report FAIL at_limit_passes "$(tail -n 3 "$tmp/clean")"
fi

{ body_of short 12; body_of over 151; } >"$tmp/tree/host/app/f.c"
if sh toolchain/check-function-length.sh "$tmp/tree" >"$tmp/planted" 2>&1; then
    report FAIL planted_long_function_fails "a 151-line function passed"
else
    report PASS planted_long_function_fails
fi
# short: 2 declaration lines + 12; over's signature starts on line 17
if grep -q '^check-function-length: host/app/f.c:17: over is 151 lines (at most 150)$' "$tmp/planted"; then
    report PASS planted_long_function_named
else
    report FAIL planted_long_function_named "no host/app/f.c:17 line in: $(head -n 3 "$tmp/planted")"
fi

if sh toolchain/check-function-length.sh . >"$tmp/real" 2>&1; then
    report PASS real_tree_passes
else
    report FAIL real_tree_passes "$(head -n 8 "$tmp/real" | tr '\n' '|')"
fi
