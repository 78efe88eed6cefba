#!/bin/sh
# Guest: the libcamera camera on vimc (camhead_libcamera_vm_check). vimc.ko,
# built from Debian's linux-source (build_vimc.sh), is loaded here and
# unloaded at the end. libcamera's IPA module for vimc (ipa_vimc.so, its
# .sign, vimc_ipa_proxy) and vimc.conf are packed at the paths libcamera was
# built with, so it needs no LIBCAMERA_IPA_MODULE_PATH, _PROXY_PATH or
# _CONFIG_PATH. Without udevd libudev calls every device uninitialised and
# libcamera lists no camera: an empty /run/udev/data/c<MAJOR>:<MINOR> per
# video4linux and media node is what udevd would have left.
results="libcamera_list libcamera_adjusted_size libcamera_capture libcamera_timestamps
libcamera_sequence libcamera_content libcamera_requeue libcamera_rgb_order"
say() {
  for name in $results; do
    echo "RESULT $name: $1"
  done
}

if ! command -v camhead_libcamera_vm_check >/dev/null; then
  say "SKIP the lab was built without libcamera-dev or libcamera-ipa (cmake/bootstrap.sh installs them)"
  exit 0
fi
if [ ! -e "/lib/modules/$(uname -r)/extra/vimc.ko" ]; then
  say "SKIP vimc.ko is not in the lab"
  exit 0
fi
modprobe vimc || {
  say "FAIL modprobe vimc failed"
  exit 1
}
[ -e /sys/bus/media/devices/media0/dev ] || {
  say "FAIL vimc loaded but made no media device"
  rmmod vimc
  exit 1
}
mkdir -p /run/udev/data
for dev in /sys/class/video4linux/*/dev /sys/bus/media/devices/*/dev; do
  [ -e "$dev" ] && : >"/run/udev/data/c$(cat "$dev")"
done

status=0
# libcamera's warnings about vimc's missing sensor data are noise here.
LIBCAMERA_LOG_LEVELS='*:ERROR' LIBCAMERA_LOG_NO_COLOR=1 camhead_libcamera_vm_check || status=$?
rm -rf /run/udev
rmmod vimc || echo "LAB libcamera_vimc: rmmod vimc failed (still in use?)"
exit "$status"
