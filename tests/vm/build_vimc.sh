#!/usr/bin/env bash
# Builds vimc.ko out of tree for the hardware lab.
#
#   build_vimc.sh LINUX_SOURCE_TARBALL HEADERS_DIR OUT_DIR
#
# Debian's kernels leave CONFIG_VIDEO_VIMC unset. The driver builds unchanged
# from its folder of Debian's own linux-source package (never committed
# here), drivers/media/test-drivers/vimc/; what it needs (videobuf2, v4l2-tpg,
# videodev, mc) is in Debian's kernel and is packed with it.
set -euo pipefail

if [ $# -ne 3 ]; then
  echo "usage: $0 LINUX_SOURCE_TARBALL HEADERS_DIR OUT_DIR" >&2
  exit 2
fi
tarball=$1 headers=$2 out=$3

work="$out/src"
rm -rf "$work"
mkdir -p "$work"

# Named one by one so that --occurrence stops reading once all are found.
top=$(basename "$tarball" .tar.xz)
files=(Makefile vimc-capture.c vimc-common.c vimc-common.h vimc-core.c vimc-debayer.c
  vimc-lens.c vimc-scaler.c vimc-sensor.c vimc-streamer.c vimc-streamer.h)
tar -xJf "$tarball" -C "$work" --strip-components=5 --occurrence=1 \
  "${files[@]/#/$top/drivers/media/test-drivers/vimc/}"

# Kbuild's own chatter (and "Skipping BTF generation") only matters on failure.
if ! log=$(make -C "$headers" M="$work" CONFIG_VIDEO_VIMC=m -j2 modules 2>&1); then
  echo "$log" >&2
  echo "build_vimc.sh: building vimc.ko against $headers failed" >&2
  exit 1
fi
# Without its debug information (2.5 MB of it) the guest unpacks less.
strip --strip-debug -o "$out/vimc.ko" "$work/vimc.ko"
