#!/usr/bin/env bash
# Installs camhead's dependencies (Debian 12 packages only), configures and
# builds. Idempotent: a second run only rebuilds what changed.
#
#   cmake/bootstrap.sh [--run] [BUILD_DIR] [extra cmake -D options...]
#
# --run: only what `camhead run` needs (README command 1, the moving rig):
#   the packages that build camhead and the modules it opens at run time (the
#   marker tracker's OpenCV, the operator page's libevent), and camhead with
#   those modules alone; no tests, benchmarks, hardware lab or libcamera,
#   which a later run without --run adds to the same build folder.
# Without it, everything (README command 2, CI): the test suite, the
#   benchmarks, the hardware lab's QEMU guest and kernel modules, and the
#   modules of the boards that need OpenCV or libcamera.
#
# Environment: CAMHEAD_SKIP_APT=1 skips apt-get (packages already present).
set -euo pipefail
cd "$(dirname "$0")/.."
run_only=0
args=()
for arg in "$@"; do
  if [ "$arg" = --run ]; then
    run_only=1
  else
    args+=("$arg")
  fi
done
set -- "${args[@]+"${args[@]}"}"
build_dir=build
if [ $# -gt 0 ] && [[ $1 != -* ]]; then
  build_dir=$1
  shift
fi

# What building camhead takes.
run_packages=(
  build-essential cmake ninja-build pkg-config
  libvulkan-dev mesa-vulkan-drivers glslang-tools
  libglm-dev nlohmann-json3-dev libcli11-dev zlib1g-dev libpng-dev
  libtinyobjloader-dev libstb-dev libtinyexr-dev
  libgpiod-dev libusb-1.0-0-dev
  # The operator page's module (pipeline/web/libevent, `camhead run --http`):
  # libevent's evhttp, libjpeg-turbo for the preview; libcrypt (the
  # password's hash) comes with libc6-dev.
  libevent-dev libturbojpeg0-dev
  # hal/output/drm: the kernel's DRM uapi headers (drm.h, drm_mode.h), which
  # Debian ships in libdrm-dev only; nothing links libdrm.
  libdrm-dev
  # The marker pose source's module (pipeline/tracking/opencv), which the
  # moving rig of README command 1 (board/sim-moving.json) tracks with:
  # OpenCV 4.6 with contrib's aruco; camhead itself opens the module at run
  # time. On a fresh Debian 12, 302 more packages and 192 MB more of the
  # download (bench/RESULTS.md, "README command 1 runs the moving rig").
  libopencv-dev libopencv-contrib-dev
)
# What the tests, benchmarks, tools and optional modules add.
test_packages=(
  git clang-format vulkan-tools
  # The service unit's tests: systemd-analyze scores its hardening,
  # systemd-sysusers makes its user in a scratch root (tests/CMakeLists.txt);
  # lintian checks the Debian package (tests/package/deb_package.sh);
  # python3 plays systemd's notification socket for `systemctl reload`
  # (tests/cli/service_reload.py).
  systemd lintian python3
  # The operator page's tests (tests/web): a client in Python with Pillow,
  # NumPy and Prometheus's own parser, and headless Chromium driven by
  # Selenium.
  python3-pil python3-numpy python3-prometheus-client python3-selenium
  chromium chromium-driver
  # The demo scene's bunny (scenes/ar_demo.json), which tests and
  # benchmarks render.
  glmark2-data
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
)
packages=("${run_packages[@]}")
[ "$run_only" = 1 ] || packages+=("${test_packages[@]}")

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

# The profile is set on every run (the options stay in the build folder's
# cache otherwise); options given after BUILD_DIR still win.
if [ "$run_only" = 1 ]; then
  cmake -S . -B "$build_dir" -G Ninja -DCAMHEAD_BUILD_TESTS=OFF -DCAMHEAD_BUILD_BENCH=OFF "$@" \
    >/dev/null
  cmake --build "$build_dir" -j "$(nproc)" --target camhead
else
  cmake -S . -B "$build_dir" -G Ninja -DCAMHEAD_BUILD_TESTS=ON -DCAMHEAD_BUILD_BENCH=ON "$@" \
    >/dev/null
  cmake --build "$build_dir" -j "$(nproc)"
fi
