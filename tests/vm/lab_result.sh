#!/usr/bin/env bash
# vm.<name>: one check's verdict from the lab's single boot (run_lab.sh).
#
#   lab_result.sh LAB_DIR NAME SCRIPT
#
# Passes on `RESULT NAME: PASS`; fails on FAIL, when the guest printed no
# line for NAME (the check crashed, hung or never ran), or when SCRIPT, the
# guest script that prints it, exited non-zero (a crash or a sanitizer report
# after the line). Skips (77) when vm.boot skipped, or when the guest printed
# `RESULT NAME: SKIP reason` (a check whose part of the lab this machine
# could not build).
set -euo pipefail
lab_dir=$1 name=$2 script=$3
results="$lab_dir/results.txt" console="$lab_dir/console.log"

if [ ! -e "$results" ]; then
  echo "no $results: vm.boot has not run"
  exit 1
fi
if head -n1 "$results" | grep -q '^SKIP '; then
  head -n1 "$results" | cut -d' ' -f2-
  exit 77
fi

lines=$(grep -a "^RESULT $name: " "$results" || true)
if grep -q "^RESULT $name: SKIP" <<<"$lines"; then
  echo "$lines"
  exit 77
fi
if [ -z "$lines" ]; then
  echo "no RESULT line for $name: the check crashed, hung or never ran; the guest console follows"
elif ! grep -q "^RESULT $name: FAIL" <<<"$lines" && grep -q "^RESULT $name: PASS" <<<"$lines"; then
  echo "$lines"
  exited=$(grep -a "^LAB check $script exited" "$console" || true)
  if [ -z "$exited" ]; then
    exit 0
  fi
  echo "but: $exited (a crash or a sanitizer report after the RESULT line?); the guest console follows"
else
  echo "$lines"
  echo "the guest console follows"
fi
echo "---- $console ----"
cat "$console"
exit 1
