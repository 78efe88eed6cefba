#!/bin/sh
# Guest: the V4L2 loopback sink and the camera on v4l2loopback
# (camhead_v4l2_loopback_check). The module, built from Debian's
# v4l2loopback-dkms source (build_v4l2loopback.sh), is loaded here with the
# options Chrome needs (exclusive_caps=1) and unloaded at the end. Where the
# build machine had no v4l2loopback source the module is not in the lab and
# the results skip.
results="v4l2_loopback_open v4l2_loopback_round_trip v4l2_loopback_close v4l2_loopback_nv12 v4l2_loopback_mjpeg"
say() {
  for name in $results; do
    echo "RESULT $name: $1"
  done
}

if [ ! -e "/lib/modules/$(uname -r)/extra/v4l2loopback.ko" ]; then
  say "SKIP v4l2loopback.ko is not in the lab (install v4l2loopback-dkms: cmake/bootstrap.sh)"
  exit 0
fi
if ! modprobe v4l2loopback video_nr=10 exclusive_caps=1 card_label=camhead; then
  say "FAIL modprobe v4l2loopback failed"
  exit 1
fi
[ -c /dev/video10 ] || {
  say "FAIL v4l2loopback loaded but /dev/video10 is missing"
  exit 1
}

status=0
camhead_v4l2_loopback_check /dev/video10 || status=$?
rmmod v4l2loopback || echo "LAB v4l2_loopback: rmmod v4l2loopback failed (still in use?)"
exit "$status"
