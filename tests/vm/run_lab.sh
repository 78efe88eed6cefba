#!/usr/bin/env bash
# vm.boot: boots the hardware lab once under QEMU (TCG, no KVM needed) and
# leaves the guest's RESULT lines in OUT_DIR/results.txt for the vm.<result>
# tests (lab_result.sh), the whole console in OUT_DIR/console.log.
#
#   run_lab.sh --out-dir DIR --skip MESSAGE
#   run_lab.sh --out-dir DIR --qemu QEMU --kernel VMLINUZ --initrd CPIO.GZ
#              [--timeout SECONDS] [--expect "name name ..."]
#              [--python3 PYTHON --screen-helper screen_helper.py]
#
# The guest has a display (-vga std: bochs-drm once loaded) and a second
# serial port, its /dev/ttyS1, on a socket that screen_helper.py serves
# while the guest runs: it takes screendumps through the QEMU monitor's
# socket when a check asks (the drm checks), and leaves them in
# OUT_DIR/screens with its log. Without --screen-helper nobody answers
# there, and those checks skip their screen results.
#
# Exit status: 0 when the guest ran to the end (whatever its checks said: a
# failing fixture would keep ctest from running, and reporting, the
# per-check tests); 77 (skip) with a message where this machine cannot run
# the lab; 1 when qemu or the guest did not get to the end.
set -euo pipefail

out_dir='' skip='' qemu='' kernel='' initrd='' timeout_s=300 expect=''
python3='' screen_helper=''
while [ $# -gt 0 ]; do
  case $1 in
  --out-dir) out_dir=$2 ;;
  --skip) skip=$2 ;;
  --qemu) qemu=$2 ;;
  --kernel) kernel=$2 ;;
  --initrd) initrd=$2 ;;
  --timeout) timeout_s=$2 ;;
  --expect) expect=$2 ;;
  --python3) python3=$2 ;;
  --screen-helper) screen_helper=$2 ;;
  *)
    echo "run_lab.sh: unknown argument $1" >&2
    exit 2
    ;;
  esac
  shift 2
done

mkdir -p "$out_dir"
results="$out_dir/results.txt" console="$out_dir/console.log"
rm -f "$results" "$console"

skip_lab() {
  echo "SKIP $1" >"$results"
  echo "$1"
  exit 77
}
[ -z "$skip" ] || skip_lab "$skip"
command -v "$qemu" >/dev/null || skip_lab "hardware lab skipped: no $qemu (apt-get install qemu-system-x86)"
[ -r "$kernel" ] || skip_lab "hardware lab skipped: cannot read the kernel image $kernel"
if [ ! -s "$initrd" ]; then
  echo "run_lab.sh: no $initrd: build the camhead_vm_lab target first" >&2
  exit 1
fi

# One CPU: the kernel stamps a GPIO edge in the interrupt but reads its level
# later in the interrupt thread, and gpio-sim drops edges while that thread is
# pending. With one CPU the thread (SCHED_FIFO) always runs before the check
# program writes the next edge, so the checks can demand exact counts; across
# two emulated CPUs its latency has no bound (28 of 30 bursts of 12 edges
# came out wrong when tried). One CPU also leaves the host's other core to
# the tests ctest runs alongside, and boots no slower.
# -nodefaults: no network card or option ROMs to probe; the first serial port
# is the guest's console. -vga std is the one display (the drm checks' HDMI
# stand-in); the second serial port and the monitor socket are the screen
# helper's. panic=-1 with -no-reboot turns a guest panic (PID 1 died) into
# qemu exiting instead of a hang.
# The sockets live in a folder of their own under /tmp: a socket path must
# fit in 108 bytes, which a deep build folder may not.
sockets=$(mktemp -d "${TMPDIR:-/tmp}/camhead-lab.XXXXXX")
trap 'rm -rf "$sockets"' EXIT
screens="$out_dir/screens"
rm -rf "$screens"
mkdir -p "$screens"
helper_pid=''
if [ -n "$screen_helper" ]; then
  "$python3" "$screen_helper" --monitor "$sockets/monitor.sock" \
    --control "$sockets/control.sock" --out-dir "$screens" >"$screens/helper.log" 2>&1 &
  helper_pid=$!
fi
start=$(date +%s.%N)
status=0
timeout --kill-after=10 "$timeout_s" "$qemu" -accel tcg -m 1024 -smp 1 -nodefaults \
  -display none -no-reboot -serial "file:$console" \
  -vga std -monitor "unix:$sockets/monitor.sock,server=on,wait=off" \
  -chardev "socket,id=labctl,path=$sockets/control.sock,server=on,wait=off" \
  -serial chardev:labctl \
  -kernel "$kernel" -initrd "$initrd" \
  -append "console=ttyS0 quiet loglevel=3 panic=-1" </dev/null || status=$?
elapsed=$(echo "$start $(date +%s.%N)" | awk '{ printf "%.1f", $2 - $1 }')
if [ -n "$helper_pid" ]; then
  # It exits when qemu closes the sockets; a hung one is not waited for long.
  for _ in $(seq 50); do
    kill -0 "$helper_pid" 2>/dev/null || break
    sleep 0.1
  done
  kill "$helper_pid" 2>/dev/null || true
  wait "$helper_pid" || true
fi

touch "$console"
# The serial console ends lines with CR LF.
sed -i 's/\r$//' "$console"
echo "---- guest console ($console) ----"
cat "$console"
echo "---- end of guest console ----"
if [ -s "$screens/helper.log" ]; then
  echo "---- screen helper ($screens/helper.log) ----"
  cat "$screens/helper.log"
  echo "---- end of screen helper ----"
fi
grep -a '^RESULT ' "$console" >"$results" || true

if [ "$status" -eq 124 ] || [ "$status" -eq 137 ]; then
  echo "run_lab.sh: the guest did not power off within $timeout_s s" >&2
  exit 1
fi
if [ "$status" -ne 0 ]; then
  echo "run_lab.sh: qemu failed with status $status" >&2
  exit 1
fi
if ! grep -aq '^LAB done' "$console"; then
  echo "run_lab.sh: the guest stopped before the end of its checks (see the console above)" >&2
  exit 1
fi

echo "boot and checks: $elapsed s (qemu start to power-off)"
for name in $expect; do
  line=$(grep -a "^RESULT $name: " "$results" | head -n1 || true)
  if [ -n "$line" ]; then
    echo "  ${line#RESULT }"
  else
    echo "  $name: MISSING"
  fi
done
