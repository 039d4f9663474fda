# Sourced by the system tests of a program's refusals (not a test itself: run_all.sh runs only
# test_*.sh). expect_error STATUS PATTERN ARGS...: "$bin" ARGS exits STATUS within 5 s with one
# line on stderr that matches PATTERN. Needs $bin, $tmp and fail() from the caller.
expect_error() {
    want=$1; pattern=$2; shift 2
    st=0
    timeout 5 "$bin" "$@" >"$tmp/out" 2>"$tmp/err" || st=$?
    [ "$st" = 124 ] && fail "'$*' hung"
    [ "$st" = "$want" ] || fail "'$*' exit $st, want $want: $(cat "$tmp/err")"
    [ "$(wc -l <"$tmp/err")" = 1 ] || fail "'$*' printed $(wc -l <"$tmp/err") lines: $(cat "$tmp/err")"
    grep -q -- "$pattern" "$tmp/err" || fail "'$*' said: $(cat "$tmp/err")"
    echo "ok: $* -> $(cat "$tmp/err")"
}
