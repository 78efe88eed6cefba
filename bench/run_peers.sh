#!/usr/bin/env bash
# Embree 3 against camhead on the same scenes and the same camera rays; prints
# one Markdown table (bench/RESULTS.md, "Embree as the CPU ceiling").
#
#   bench/run_peers.sh [BUILD_DIR] [embree_peer options...]
#   bench/run_peers.sh build --rpp 4 --rounds 9 --device 0
#
# For each scene, embree_peer traces the frame's camera rays with Embree
# (closest hit; rtcIntersect1, rtcIntersect16 and rtcIntersect1M on all
# cores) and, in the same process and interleaved round by round, renders
# the same frame with camhead's CPU reference and GPU tracer. The "_primary"
# scenes are the same geometry with no lights, diffuse materials, no bounces
# and everything real (bench_scenes.h): there a camhead camera ray makes one
# closest-hit query, as Embree's does. Defaults: 720x576, 1 rpp, 5 rounds
# after one warm-up round; medians.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
shift || true
peer=$build_dir/bench/embree_peer
if [ ! -x "$peer" ]; then
  echo "run_peers: $peer is not built (needs libembree-dev; cmake --build $build_dir --target embree_peer)" >&2
  exit 1
fi

cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')
echo "Machine: $(nproc) hardware threads ($cpu), $(date -u +%Y-%m-%d)."
echo "Command: bench/run_peers.sh $build_dir $*"
echo
header=()
for scene in ar_basic ar_basic_primary ar_demo ar_demo_primary; do
  "$peer" --scene "$scene" --camhead "${header[@]}" "$@"
  header=(--no-header)
done
