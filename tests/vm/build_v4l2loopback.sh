#!/usr/bin/env bash
# Builds v4l2loopback.ko out of tree for the hardware lab.
#
#   build_v4l2loopback.sh SOURCE_DIR HEADERS_DIR OUT_DIR
#
# SOURCE_DIR is what Debian's v4l2loopback-dkms installs
# (/usr/src/v4l2loopback-VERSION: v4l2loopback.c, v4l2loopback_formats.h).
# It is copied and built here rather than taken from DKMS's own build under
# /lib/modules, which exists only where DKMS ran after the headers were
# installed, and never committed. The guest loads it itself (v4l2_loopback.sh)
# with the options Chrome needs.
set -euo pipefail

if [ $# -ne 3 ]; then
  echo "usage: $0 SOURCE_DIR HEADERS_DIR OUT_DIR" >&2
  exit 2
fi
source_dir=$1 headers=$2 out=$3

work="$out/src"
rm -rf "$work"
mkdir -p "$work"
cp "$source_dir/v4l2loopback.c" "$source_dir/v4l2loopback_formats.h" "$work/"
echo 'obj-m := v4l2loopback.o' >"$work/Kbuild"

# Kbuild's own chatter (and "Skipping BTF generation") only matters on failure.
if ! log=$(make -C "$headers" M="$work" -j2 modules 2>&1); then
  echo "$log" >&2
  echo "build_v4l2loopback.sh: building v4l2loopback.ko from $source_dir against $headers failed" >&2
  exit 1
fi
# Without its debug sections (what INSTALL_MOD_STRIP does): a tenth of the
# size in the initramfs the guest unpacks under emulation.
strip --strip-debug -o "$out/v4l2loopback.ko" "$work/v4l2loopback.ko"
