#!/bin/sh
# Guest: the V4L2 loopback sink and the camera on v4l2loopback
# (camhead_v4l2_loopback_check). The module, built from Debian's
# v4l2loopback-dkms source (build_v4l2loopback.sh), is loaded here with the
# options camhead's package gives it (systemd/camhead-v4l2loopback.conf,
# packed into the lab's /etc/lab: /dev/video10, named "camhead",
# exclusive_caps=1 as Chrome needs) and unloaded at the end. Where the build
# machine had no v4l2loopback source the module is not in the lab and the
# results skip.
results="v4l2_loopback_open v4l2_loopback_round_trip v4l2_loopback_close v4l2_loopback_nv12 v4l2_loopback_mjpeg v4l2_loopback_reader_100 v4l2_loopback_v4l2ctl"
say() {
  for name in $results; do
    echo "RESULT $name: $1"
  done
}

if [ ! -e "/lib/modules/$(uname -r)/extra/v4l2loopback.ko" ]; then
  say "SKIP v4l2loopback.ko is not in the lab (install v4l2loopback-dkms: cmake/bootstrap.sh)"
  exit 0
fi
conf=/etc/lab/camhead-v4l2loopback.conf
options=$(sed -n 's/^options v4l2loopback //p' "$conf" 2>/dev/null)
if [ -z "$options" ]; then
  say "FAIL no options line in camhead-v4l2loopback.conf ('$conf')"
  exit 1
fi
# shellcheck disable=SC2086 # the options are words
if ! modprobe v4l2loopback $options; then
  say "FAIL modprobe v4l2loopback $options failed"
  exit 1
fi
[ -c /dev/video10 ] || {
  say "FAIL v4l2loopback loaded with '$options' but /dev/video10 is missing"
  exit 1
}
name=$(cat /sys/class/video4linux/video10/name 2>/dev/null)
[ "$name" = camhead ] || {
  say "FAIL /dev/video10 is named '$name', not camhead ('$options')"
  exit 1
}

status=0
camhead_v4l2_loopback_check /dev/video10 || status=$?

# An independent client reads what camhead's sink writes: v4l2-ctl (Debian's
# v4l-utils), as a webcam consumer would, frames stored raw and checked.
if command -v v4l2-ctl >/dev/null; then
  camhead_v4l2_loopback_check --write /dev/video10 3 &
  writer=$!
  sleep 0.5
  v4l2-ctl -d /dev/video10 --stream-mmap --stream-count=8 --stream-to=/tmp/v4l2ctl.raw \
    >/tmp/v4l2ctl.log 2>&1 || echo "LAB v4l2_loopback: v4l2-ctl: $(tail -1 /tmp/v4l2ctl.log)"
  wait "$writer" || echo "LAB v4l2_loopback: the writer failed"
  camhead_v4l2_loopback_check --verify /tmp/v4l2ctl.raw || status=$?
else
  echo "RESULT v4l2_loopback_v4l2ctl: SKIP v4l2-ctl is not in the lab (install v4l-utils: cmake/bootstrap.sh)"
fi
rmmod v4l2loopback || echo "LAB v4l2_loopback: rmmod v4l2loopback failed (still in use?)"
exit "$status"
