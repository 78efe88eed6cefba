#!/usr/bin/env bash
# Issue 24's GPU figures in one run, sized for a lent GPU machine's minutes
# after bench/gpu_check.sh: the renderer's tests on the GPU (every kernel
# against the CPU reference on that driver), the adaptive second pass's
# longest thread (the same mean rays with the largest share capped lower),
# the live frame (the sim rig's frame renderer, `camhead run` on the sim
# rig for 30 s with its record, and its error against time), and the
# speed-accuracy chart of uniform and adaptive sampling timed on the GPU.
# Prints Markdown; the log, the record and the charts (CSV, PNGs) go to
# OUT_DIR.
#
#   bench/gpu_live_check.sh BIN_DIR [OUT_DIR]
#
# BIN_DIR holds camhead, camhead_benchmarks and test_renderer built here
# (stripped, they travel in a few MiB; camhead_benchmarks also needs
# libbenchmark.so.1debian on LD_LIBRARY_PATH). The tests look for their
# assets under the source directory they were built in
# (CAMHEAD_SOURCE_DIR); SOURCE_DIR names it so that a link to this checkout
# can stand there. The chart's 1024-rpp references are rendered on the
# machine's CPU cores (about a minute on 16). The chart's GPU timings are
# not to be trusted (bench/RESULTS.md, "On a GPU at last"): its errors are.
# The commands that ran it on an H200 are in that section.
set -uo pipefail
cd "$(dirname "$0")/.."
bin=${1:?BIN_DIR}
out=${2:-.}
mkdir -p "$out"
log=$out/gpu_live_check.md
: >"$log"
say() { echo "$@" | tee -a "$log"; }
step() {
  say
  say "    $*"
  say
  "$@" 2>&1 | tee -a "$log"
}

if [ -n "${SOURCE_DIR:-}" ] && [ ! -e "$SOURCE_DIR" ]; then
  mkdir -p "$(dirname "$SOURCE_DIR")"
  ln -s "$PWD" "$SOURCE_DIR"
fi

say "# Issue 24 on a GPU, $(date -u +%Y-%m-%d)"

# Every renderer test, the GPU ones on this machine's driver.
step "$bin/test_renderer" --gtest_brief=1

# The second pass's longest thread: the same mean rays, the largest share
# at 16x (the default), 4x and 2x the mean; uniform 9 and 49 beside them.
for cap in 16 4 2; do
  step "$bin/camhead" bench --scene scenes/ar_demo.json --rpp 9 --adaptive --adaptive-cap "$cap" \
    --frames 21 --warmup 3
done
step "$bin/camhead" bench --scene scenes/ar_demo.json --rpp 9,49 --frames 21 --warmup 3

# The live frame: the sim rig's frame renderer alone, then the whole rig.
step "$bin/camhead_benchmarks" --benchmark_filter='LiveFrame/gpu'
step "$bin/camhead" run --board sim --executor gpu --duration 30 --output null \
  --record-stats "$out/run_gpu.jsonl"
# The live frame's error against time on this driver (its exp and cube
# root in the reconstruction): lavapipe's figures are in bench/RESULTS.md,
# "The GPU executor reconstructs". Its references take about a minute on
# 16 cores.
step "$bin/camhead" bench live --executor gpu -o "$out/live"

# Speed against accuracy, timed on the GPU.
# The references stay behind in the chart's cache; the CSV and the charts
# come back.
step "$bin/camhead" bench chart tests/assets/reference/ar_basic.json scenes/ar_demo.json \
  --scale 0.5 --methods uniform,adaptive -o /tmp/gpu_chart
cp /tmp/gpu_chart/chart*.csv /tmp/gpu_chart/chart*.png "$out"/
