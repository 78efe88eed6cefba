#!/usr/bin/env bash
# Installs camhead's build and test dependencies (Debian 12 packages only),
# configures and builds. Idempotent: a second run only rebuilds what changed.
#
#   cmake/bootstrap.sh [BUILD_DIR] [extra cmake -D options...]
#
# Environment: CAMHEAD_SKIP_APT=1 skips apt-get (packages already present).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
shift || true

packages=(
  build-essential cmake ninja-build pkg-config git clang-format
  libvulkan-dev mesa-vulkan-drivers glslang-tools vulkan-tools
  libglm-dev nlohmann-json3-dev libcli11-dev zlib1g-dev libpng-dev
  libtinyobjloader-dev libstb-dev libtinyexr-dev glmark2-data
  libgpiod-dev libusb-1.0-0-dev
  # The marker pose source's module (pipeline/tracking/opencv): OpenCV 4.6
  # with contrib's aruco; camhead itself opens the module at run time.
  libopencv-dev libopencv-contrib-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  # bench/embree_peer: Embree 3 as the CPU ceiling for ray throughput.
  libembree-dev
  clang libclang-rt-14-dev
  # The hardware lab (tests/vm): QEMU boots Debian's kernel with gpio-sim
  # built from its source against its headers (all three from one release).
  qemu-system-x86 linux-image-amd64 linux-headers-amd64 linux-source-6.1
  busybox-static cpio kmod xz-utils
  # The lab's virtual webcam (tests/vm/v4l2_loopback.sh): the package is the
  # driver's source, which the lab builds against the same headers as
  # gpio-sim (build_v4l2loopback.sh). Installing it also runs DKMS once.
  v4l2loopback-dkms
  # The lab's independent V4L2 client: v4l2-ctl reads what the loopback
  # sink writes (tests/vm/v4l2_loopback.sh).
  v4l-utils
  # hal/camera/libcamera: the headers and library its module links
  # (camhead itself opens the module at run time), and the vimc IPA module
  # the lab's libcamera check packs (tests/vm/libcamera_vimc.sh).
  libcamera-dev libcamera-ipa
  # hal/output/drm: the kernel's DRM uapi headers (drm.h, drm_mode.h), which
  # Debian ships in libdrm-dev only; nothing links libdrm.
  libdrm-dev
)

if [ "${CAMHEAD_SKIP_APT:-0}" != 1 ]; then
  missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "bootstrap: installing ${missing[*]}" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -q
    apt-get install -y -q --no-install-recommends "${missing[@]}"
  fi
fi

cmake -S . -B "$build_dir" -G Ninja "$@" >/dev/null
cmake --build "$build_dir" -j "$(nproc)"
