#!/bin/sh
# The Debian package as a user gets it: `cpack -G DEB` in BUILD_DIR, then
# its contents, its control fields and scripts, lintian where installed,
# and camhead run from the package's files unpacked into a scratch root
# (its data found beside the binary, as on an installed box).
#
#   tests/package/deb_package.sh BUILD_DIR SCRATCH_DIR
set -eu
build=$1
scratch=$2
rm -rf "$scratch"
mkdir -p "$scratch"
fail() {
  echo "FAIL $*"
  exit 1
}

(cd "$build" && cpack -G DEB -B "$scratch/out" >"$scratch/cpack.log" 2>&1) ||
  { cat "$scratch/cpack.log"; fail "cpack"; }
deb=$(ls "$scratch"/out/camhead_*.deb)
echo "package: $(basename "$deb"), $(du -k "$deb" | cut -f1) KiB"

dpkg-deb -c "$deb" | awk '{print $6}' | sed 's|^\./|/|' >"$scratch/contents"
for path in /usr/bin/camhead /usr/lib/systemd/system/camhead@.service \
  /usr/lib/sysusers.d/camhead.conf /usr/share/camhead/board/sim.json \
  /usr/share/camhead/scenes/sim_rig.json /usr/share/camhead/scenes/lenses/example_35mm.json \
  /usr/share/doc/camhead/copyright /usr/lib/udev/rules.d/70-camhead-lens.rules \
  /usr/lib/modprobe.d/camhead-v4l2loopback.conf /usr/lib/modules-load.d/camhead.conf; do
  grep -qx "$path" "$scratch/contents" || fail "$path is not in the package"
done
# The operator page's module, where the build made it, beside the others.
if [ -e "$build/libcamhead_web.so" ]; then
  grep -q '^/usr/lib/.*camhead/libcamhead_web.so$' "$scratch/contents" ||
    fail "the operator page's module is not in the package"
fi
if grep -q '^/usr/local/' "$scratch/contents"; then fail "files under /usr/local"; fi

control=$(dpkg-deb -f "$deb")
echo "$control" | grep '^Depends:'
echo "$control" | grep -q '^Depends:.*libvulkan1' || fail "Depends lacks libvulkan1 (dpkg-shlibdeps)"
echo "$control" | grep -q '^Depends:.*mesa-vulkan-drivers | vulkan-icd' || fail "Depends lacks a Vulkan driver"
echo "$control" | grep -q '^Depends:.*libturbojpeg0' || fail "Depends lacks libturbojpeg0 (MJPEG, opened at run time)"
dpkg-deb -e "$deb" "$scratch/control"
grep -q 'systemd-sysusers camhead.conf' "$scratch/control/postinst" || fail "postinst makes no user"
grep -q 'install -m 0600 /dev/null /etc/camhead/web-password' "$scratch/control/postinst" ||
  fail "postinst makes no empty operator page password file"
# Every board is the administrator's too: a conffile in /etc/camhead/board.
for board in sim rpi5-libcamera-hdmi x86-uvc-webcam; do
  grep -qx "/etc/camhead/board/$board.json" "$scratch/contents" || fail "no /etc board $board"
  grep -qx "/etc/camhead/board/$board.json" "$scratch/control/conffiles" ||
    fail "/etc/camhead/board/$board.json is not a conffile"
done
if grep -v '^/etc/' "$scratch/control/conffiles"; then fail "a conffile outside /etc"; fi

if command -v lintian >/dev/null 2>&1; then
  lintian --tag-display-limit 0 "$deb" >"$scratch/lintian.log" 2>&1 || true
  cat "$scratch/lintian.log"
  if grep -q '^E:' "$scratch/lintian.log"; then fail "lintian reports errors"; fi
else
  echo "lintian: not installed, not run"
fi

# The packaged camhead runs the simulated rig from its own files.
dpkg-deb -x "$deb" "$scratch/root"
(cd "$scratch" && env -u CAMHEAD_DATA_DIR "$scratch/root/usr/bin/camhead" run --frames 2 \
  --output null >"$scratch/run.log" 2>&1) || { cat "$scratch/run.log"; fail "the packaged camhead"; }
# Its status line names the lens trace it read: the package's own.
grep -q "trace $scratch/root/usr/share/camhead/scenes/lenses/" "$scratch/run.log" ||
  { cat "$scratch/run.log"; fail "the packaged camhead read its data from elsewhere"; }
# An administrator's edit of the /etc board is what `--board sim` runs
# (CAMHEAD_CONFIG_DIR stands for /etc/camhead in the scratch root); its
# relative paths still find the packaged scenes and lens files.
sed -i 's/"name": "focus pull"/"name": "edited pull"/' "$scratch/root/etc/camhead/board/sim.json"
(cd "$scratch" && env -u CAMHEAD_DATA_DIR CAMHEAD_CONFIG_DIR="$scratch/root/etc/camhead" \
  "$scratch/root/usr/bin/camhead" run --frames 2 --output null >"$scratch/run_etc.log" 2>&1) ||
  { cat "$scratch/run_etc.log"; fail "the packaged camhead on its /etc board"; }
grep -q "lens edited pull \[trace $scratch/root/usr/share/camhead/scenes/lenses/" \
  "$scratch/run_etc.log" || { cat "$scratch/run_etc.log"; fail "the /etc board was not the one run"; }
echo "PASS"
