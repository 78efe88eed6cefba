#!/bin/sh
# Frame time with and without the influence region (renderer
# influence_region.h) on lavapipe and the CPU reference, in one process per
# setting: bench/RESULTS.md, "Issue 11". Usage: bench/influence_region.sh [BUILD]
# About 75 minutes on 2 cores; the demo at 1920x1080 is most of it.
set -e
camhead=${1:-build}/camhead
for scene in tests/assets/reference/ar_basic.json scenes/ar_demo.json bench/scenes/small_ball.json; do
  echo "## $scene"
  "$camhead" bench --influence-region --cpu-peer --scene "$scene" --rpp 1,25,49 --frames 3 --warmup 1
  "$camhead" bench --influence-region --cpu-peer --scene "$scene" --rpp 25 --adaptive --frames 3 --warmup 1
  "$camhead" bench --influence-region --cpu-peer --scene "$scene" --width 1920 --height 1080 \
    --rpp 1,25,49 --frames 3 --warmup 1
  "$camhead" bench --influence-region --cpu-peer --scene "$scene" --width 1920 --height 1080 \
    --rpp 25 --adaptive --frames 3 --warmup 1
done
