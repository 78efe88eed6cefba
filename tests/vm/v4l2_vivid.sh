#!/bin/sh
# Guest: the V4L2 camera against vivid (camhead_v4l2_vivid_check). vivid is
# packed but not loaded at boot: it is loaded here with one capture node,
# its error-injection controls (Disconnect, Inject V4L2_BUF_FLAG_ERROR) on,
# and unloaded at the end, leaving the lab as it was.
results="v4l2_vivid_yuyv v4l2_vivid_nv12 v4l2_vivid_wrong_size v4l2_vivid_error_buffer
v4l2_vivid_disconnect v4l2_vivid_reconnect v4l2_vivid_reconnect_100"
fail() {
  for name in $results; do
    echo "RESULT $name: FAIL $1"
  done
  exit 1
}

modprobe vivid n_devs=1 node_types=0x1 || fail "modprobe vivid failed"
device=
for node in /sys/class/video4linux/video*; do
  [ "$(cat "$node/name" 2>/dev/null)" = "vivid-000-vid-cap" ] && device=/dev/${node##*/}
done
[ -n "$device" ] || fail "vivid loaded but made no vivid-000-vid-cap node"
[ -c "$device" ] || fail "$device is not a device node (devtmpfs)"

status=0
camhead_v4l2_vivid_check "$device" || status=$?
rmmod vivid || echo "LAB v4l2_vivid: rmmod vivid failed (still in use?)"
exit "$status"
