# What the hostile-input scripts share (sourced, after setting `tmp`):
# fail MESSAGE counts a failure; expect STATUS PATTERN COMMAND... runs the
# command and checks that it exits with STATUS and says PATTERN.
failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}
expect() {
  want=$1
  pattern=$2
  shift 2
  "$@" >"$tmp/out" 2>&1
  got=$?
  [ "$got" -eq "$want" ] || fail "$* exited $got, not $want: $(cat "$tmp/out")"
  grep -q -- "$pattern" "$tmp/out" || fail "$* did not say '$pattern': $(cat "$tmp/out")"
}
