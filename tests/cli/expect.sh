# What the hostile-input scripts share (sourced, with the script's own
# arguments CAMHEAD SOURCE_DIR): `camhead`, `src`, a scratch folder `tmp`
# removed on exit; fail MESSAGE counts a failure; expect STATUS PATTERN
# COMMAND... runs the command and checks that it exits with STATUS and says
# PATTERN.
set -u
camhead=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
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
