#!/bin/sh
# Guest: the USB lens-encoder board (docs/usb-lens-protocol.md) as a configfs
# gadget with one FunctionFS function on dummy_hcd, served by
# camhead_usb_lens_gadget and read through open_usb_lens() by
# camhead_usb_vm_check, which prints the RESULT lines:
#
#   1. the checker starts before the gadget is bound (board absent);
#   2. bind the UDC: the board enumerates and streams COUNT reports, report
#      CORRUPT of them corrupted;
#   3. once the gadget has sent them (its done file says "done 1"), unplug:
#      unbind the UDC with the checker's transfers still queued;
#   4. a second later replug: bind again; the board starts over and sends
#      COUNT more; the checker exits when it has them;
#   5. unplug and plug again and again: 10 times read by the backend alone
#      (camhead_usb_replug_check), then, the gadget started again streaming
#      without end, 100 times (10 under the sanitizers) while `camhead run`
#      composites frames with the board's lens (camhead_usb_run_check).
#
# busybox sh; no bash. Needs configfs mounted at /sys/kernel/config and the
# modules dummy_hcd, libcomposite and usb_f_fs (guest_init.sh loads them; the
# modprobes below are for running this alone). Leaves the UDC free.
gadget=/sys/kernel/config/usb_gadget/g1
ffs=/dev/ffs-lens
done_file=/tmp/usb_lens.done
ready_file=/tmp/usb_vm_check.ready
count=200   # reports per connection: 1 s at 200 Hz
rate=200
corrupt=50  # index of the corrupted report in the first connection
serial=VM0001
results="usb_absent_at_start usb_enumerates_and_streams usb_counts_match_trajectory
usb_clock_mapping usb_corrupt_report_malformed usb_unplug_replug usb_replug_backend usb_replug_100"
server=
checker=

cleanup() {
  [ -e "$gadget/UDC" ] && echo "" >"$gadget/UDC" 2>/dev/null
  [ -n "$checker" ] && kill "$checker" 2>/dev/null && wait "$checker" 2>/dev/null
  [ -n "$server" ] && kill "$server" 2>/dev/null && wait "$server" 2>/dev/null
  umount "$ffs" 2>/dev/null
  rm -f "$gadget/configs/c.1/ffs.lens"
  for dir in configs/c.1/strings/0x409 configs/c.1 functions/ffs.lens strings/0x409 ""; do
    if [ -d "$gadget/$dir" ]; then rmdir "$gadget/$dir"; fi
  done
  rm -f "$done_file" "$ready_file"
}
# Before the checker runs, a failure fails every result it would have printed.
fail() {
  for name in $results; do
    echo "RESULT $name: FAIL $1"
  done
  cleanup
  exit 1
}
# wait_for SECONDS COMMAND...: polls every 50 ms.
wait_for() {
  limit=$(($1 * 20))
  shift
  tries=0
  until "$@"; do
    tries=$((tries + 1))
    [ "$tries" -le "$limit" ] || return 1
    sleep 0.05
  done
}

modprobe dummy_hcd 2>/dev/null
modprobe libcomposite 2>/dev/null
modprobe usb_f_fs 2>/dev/null
[ -d /sys/kernel/config/usb_gadget ] || mount -t configfs configfs /sys/kernel/config 2>/dev/null
udc=
for path in /sys/class/udc/*; do
  [ -e "$path" ] && udc=${path##*/} && break
done
[ -n "$udc" ] || fail "no UDC in /sys/class/udc (dummy_hcd not loaded)"

# The board's device descriptor and strings (the protocol's section 2).
mkdir "$gadget" || fail "cannot create $gadget (configfs, libcomposite)"
echo 0x1209 >"$gadget/idVendor"  # pid.codes
echo 0x0001 >"$gadget/idProduct" # pid.codes TEST PID
echo 0x0100 >"$gadget/bcdDevice"
echo 0x0200 >"$gadget/bcdUSB"
mkdir "$gadget/strings/0x409"
echo "camhead" >"$gadget/strings/0x409/manufacturer"
echo "camhead lens encoder" >"$gadget/strings/0x409/product"
echo "$serial" >"$gadget/strings/0x409/serialnumber"
mkdir "$gadget/configs/c.1"
mkdir "$gadget/configs/c.1/strings/0x409"
echo "lens" >"$gadget/configs/c.1/strings/0x409/configuration"
echo 100 >"$gadget/configs/c.1/MaxPower"
mkdir "$gadget/functions/ffs.lens" || fail "cannot create a FunctionFS function (usb_f_fs)"
ln -s "$gadget/functions/ffs.lens" "$gadget/configs/c.1/"
mkdir -p "$ffs"
mount -t functionfs lens "$ffs" || fail "cannot mount functionfs at $ffs"

# The board: descriptors to ep0, then ep1 appears.
: >"$done_file"
camhead_usb_lens_gadget --ffs "$ffs" --rate "$rate" --count "$count" --corrupt-at "$corrupt" \
  --done-file "$done_file" &
server=$!
wait_for 5 test -e "$ffs/ep1" || fail "the gadget program wrote no descriptors within 5 s"

# 1. The host side first, with no board on the bus.
rm -f "$ready_file"
camhead_usb_vm_check --count "$count" --rate "$rate" --corrupt-at "$corrupt" --connections 2 \
  --serial "$serial" --timeout-s 60 --ready-file "$ready_file" &
checker=$!
wait_for 10 test -e "$ready_file" || echo "LAB usb_lens: the checker did not start within 10 s"

# 2. Plug.
echo "$udc" >"$gadget/UDC" || fail "cannot bind the gadget to $udc"
# 3. Unplug once the first connection's reports are out.
if ! wait_for 30 grep -qs "^done 1 " "$done_file"; then
  echo "LAB usb_lens: the gadget did not finish its first connection within 30 s" \
    "(UDC state $(cat "/sys/class/udc/$udc/state"))"
fi
echo "" >"$gadget/UDC"
sleep 1
# 4. Replug; the checker ends when the second connection is complete.
echo "$udc" >"$gadget/UDC" || echo "LAB usb_lens: cannot bind the gadget to $udc again"
# The checker's own status ends the script, so that a crash or a sanitizer
# report after its RESULT lines fails the check.
status=0
wait "$checker" || status=$?
checker=
# Then unplugged and plugged back, again and again, the gadget streaming a
# burst on each connection: read by the backend alone.
camhead_usb_replug_check "$gadget/UDC" "$udc" "$serial" || status=$?
# And by `camhead run`, the board streaming for as long as it is plugged in,
# so that only the unplug can make the lens stale. The gadget program starts
# again unplugged (FunctionFS takes new descriptors once ep0 is closed).
echo "" >"$gadget/UDC"
kill "$server" 2>/dev/null
wait "$server" 2>/dev/null
camhead_usb_lens_gadget --ffs "$ffs" --rate "$rate" --count 0 &
server=$!
if wait_for 5 test -e "$ffs/ep1" && echo "$udc" >"$gadget/UDC"; then
  camhead_usb_run_check "$gadget/UDC" "$udc" "$serial" || status=$?
else
  echo "RESULT usb_replug_100: FAIL the streaming gadget did not start or bind"
  status=1
fi
cleanup
exit "$status"
