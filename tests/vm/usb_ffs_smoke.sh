#!/bin/sh
# Guest: a FunctionFS gadget on dummy_hcd, served and probed by
# camhead_vm_usb_smoke. Leaves the UDC free for the checks after it. Exits
# with the probe's status (non-zero: it crashed).
gadget=/sys/kernel/config/usb_gadget/lab-smoke
ffs=/dev/ffs-lab-smoke
vid=1209 # pid.codes test VID:PID
pid=0001
server=

cleanup() {
  [ -e "$gadget/UDC" ] && echo "" >"$gadget/UDC" 2>/dev/null
  [ -n "$server" ] && kill "$server" 2>/dev/null && wait "$server" 2>/dev/null
  umount "$ffs" 2>/dev/null
  rm -f "$gadget/configs/c.1/ffs.smoke"
  for dir in configs/c.1/strings/0x409 configs/c.1 functions/ffs.smoke strings/0x409 ""; do
    [ -d "$gadget/$dir" ] && rmdir "$gadget/$dir"
  done
}
fail() {
  echo "RESULT usb_ffs_enumerate: FAIL $1"
  echo "RESULT usb_ffs_bulk_echo: FAIL not reached"
  cleanup
  exit 1
}

udc=
for path in /sys/class/udc/*; do
  [ -e "$path" ] && udc=${path##*/} && break
done
[ -n "$udc" ] || fail "no UDC in /sys/class/udc (dummy_hcd not loaded)"
mkdir "$gadget" || fail "cannot create $gadget (libcomposite, configfs)"
echo "0x$vid" >"$gadget/idVendor"
echo "0x$pid" >"$gadget/idProduct"
mkdir "$gadget/strings/0x409"
echo "camhead lab" >"$gadget/strings/0x409/manufacturer"
echo "FunctionFS smoke" >"$gadget/strings/0x409/product"
echo "0001" >"$gadget/strings/0x409/serialnumber"
mkdir "$gadget/configs/c.1"
mkdir "$gadget/functions/ffs.smoke" || fail "cannot create a FunctionFS function (usb_f_fs)"
ln -s "$gadget/functions/ffs.smoke" "$gadget/configs/c.1/"
mkdir -p "$ffs"
mount -t functionfs smoke "$ffs" || fail "cannot mount functionfs"

camhead_vm_usb_smoke gadget "$ffs" &
server=$!
tries=0
while [ ! -e "$ffs/ep2" ]; do
  tries=$((tries + 1))
  [ "$tries" -le 100 ] || fail "the gadget program wrote no descriptors within 5 s"
  sleep 0.05
done
echo "$udc" >"$gadget/UDC" || fail "cannot bind the gadget to $udc"
# dummy_hcd's root hub enumerates the gadget; the host side starts once the
# UDC says the host configured it.
tries=0
while [ "$(cat "/sys/class/udc/$udc/state")" != configured ]; do
  tries=$((tries + 1))
  if [ "$tries" -gt 200 ]; then
    dmesg | tail -n 20
    fail "$udc is still $(cat "/sys/class/udc/$udc/state") 10 s after binding"
  fi
  sleep 0.05
done
echo "LAB usb: $udc configured after $((tries * 50)) ms"

# Its RESULT lines say how the check went; its exit status whether it crashed.
camhead_vm_usb_smoke host "$vid" "$pid"
status=$?
cleanup
exit "$status"
