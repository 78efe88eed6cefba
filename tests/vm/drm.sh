#!/bin/sh
# Guest: the DRM/KMS sink on QEMU's standard VGA (camhead_drm_vm_check).
# bochs is packed but loaded here: it makes /dev/dri/card0 and, through the
# kernel's fbdev emulation, a text console on it (fbcon), which is what the
# sink must leave on screen when it closes. The text written to that console
# first gives the before/after screendumps something to compare, and its
# cursor is hidden so that a blink cannot tell two dumps apart. The screen is
# read on the host (screen_helper.py, over /dev/ttyS1). bochs stays loaded:
# fbcon holds it.
results="drm_master_busy drm_frame_too_large drm_open drm_placeholder drm_frame drm_flip
drm_close_restores_crtc drm_console_back drm_full_frame drm_destructor_restores drm_card_back"
fail() {
  for name in $results; do
    echo "RESULT $name: FAIL $1"
  done
  exit 1
}

modprobe bochs || fail "modprobe bochs failed"
waited=0
until [ -c /dev/dri/card0 ]; do
  [ "$waited" -lt 50 ] || fail "bochs loaded but no /dev/dri/card0 (is qemu run with -vga std?)"
  sleep 0.1
  waited=$((waited + 1))
done
if [ -c /dev/tty1 ]; then
  printf '\033[?25l\033[2J\033[Hcamhead hardware lab: the DRM sink check\n' >/dev/tty1
  # fbcon draws into a shadow buffer that a worker copies out; give it time.
  sleep 1
fi
camhead_drm_vm_check /dev/ttyS1
