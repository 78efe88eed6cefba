#!/usr/bin/env bash
# Issue 11's GPU figures in one run, sized for a lent GPU machine's 15
# minutes: the demo scene against the paper's frame rates at 25 and 49 rpp,
# and 1920x1080 at 49-rpp quality (adaptive 9 rpp has the error of uniform
# 49: RESULTS, "Speed versus accuracy"), each over every pixel and over the
# influence region; then the device's own time of an adaptive 1080p frame
# beside the host's, and last the trace kernel with every feature. Prints
# Markdown; every line also goes to OUT_DIR/gpu_check.md.
#
#   bench/gpu_check.sh [BUILD_DIR] [OUT_DIR]
#
# The machine needs a Vulkan driver and loader, nothing else: build here and
# carry BUILD_DIR/camhead (RESULTS, "Frame rate on an NVIDIA H100"), and the
# demo's bunny at /usr/share/glmark2/models/bunny.obj (glmark2-data; RESULTS,
# "On a GPU at last", has the commands). FRAMES
# and WARMUP (21 and 3) set the frames timed per setting. On lavapipe,
# QUICK=1 FRAMES=1 WARMUP=0 checks the script in two minutes (720x576 only).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
out_dir=${2:-.}
camhead=$build_dir/camhead
frames=${FRAMES:-21}
warmup=${WARMUP:-3}
quick=${QUICK:-0}
mkdir -p "$out_dir"
log=$out_dir/gpu_check.md
: >"$log"

say() { echo "$@" | tee -a "$log"; }
bench() {
  say
  say "    camhead bench $*"
  say
  "$camhead" bench --frames "$frames" --warmup "$warmup" "$@" 2>&1 | tee -a "$log"
}

say "# Issue 11 on a GPU, $(date -u +%Y-%m-%d) (each table names its device)"

# The paper: 59 / 12 / 7 fps at 1 / 25 / 49 rpp, 720x576 (method.md 4).
bench --scene scenes/ar_demo.json --rpp 1,25,49 --influence-region
bench --scene scenes/ar_demo.json --rpp 9,25 --adaptive --influence-region
bench --scene tests/assets/reference/ar_basic.json --rpp 1,25,49 --influence-region
if [ "$quick" = 1 ]; then
  exit 0
fi
# 1080p at 49-rpp quality: the goal is 60 fps (16.7 ms a frame).
for scene in tests/assets/reference/ar_basic.json scenes/ar_demo.json; do
  bench --scene "$scene" --width 1920 --height 1080 --rpp 9 --adaptive --influence-region
  bench --scene "$scene" --width 1920 --height 1080 --rpp 49 --influence-region
done
# Device time against host time for the adaptive frame (allocation included).
bench --scene scenes/ar_demo.json --width 1920 --height 1080 --rpp 9 --adaptive
# What building the trace kernel for the scene saves on a GPU: against the
# every-pixel 25-rpp rows above (RESULTS, "The kernel built for the scene").
for scene in tests/assets/reference/ar_basic.json scenes/ar_demo.json; do
  bench --scene "$scene" --rpp 25 --every-kernel-feature
done
