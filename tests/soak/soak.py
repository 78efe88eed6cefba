#!/usr/bin/env python3
"""A long run of `camhead run` on the simulated rig, watched from outside.

The rig is the simulated one (the sim rig's scene, lens profile and looped
focus pull) at a small size, so that the camera's 25 fps hold beside other
work and what is measured is the pipeline, not the tracer. From outside, as
a service manager sees the process:

  memory      VmRSS each second; the growth is the median of the last 10 s
              less the median of the 10 s after warm-up (a quarter of the
              run, at least 10 s). Must stay under 1 MiB.
  descriptors /proc/PID/fd at the end of warm-up and at the end: equal.
  threads     /proc/PID/status Threads: likewise.
  frames      the frames the outputs got (composites, repeats and
              placeholders, from --record-stats) between the end of
              warm-up and the end, against 25 a second: within 0.1 %.

    soak.py CAMHEAD SOURCE_DIR SCRATCH_DIR SECONDS

Prints a line per figure, then PASS or FAIL with what failed; --json FILE
writes the figures.
"""
import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import time

parser = argparse.ArgumentParser()
parser.add_argument("camhead")
parser.add_argument("source", type=os.path.abspath)
parser.add_argument("scratch", type=os.path.abspath)
parser.add_argument("seconds", type=float)
parser.add_argument("--json")
args = parser.parse_args()

FPS = 25
os.makedirs(args.scratch, exist_ok=True)
board = os.path.join(args.scratch, "soak_board.json")
stats = os.path.join(args.scratch, "soak_stats.jsonl")
lenses = os.path.join(args.source, "scenes", "lenses")
with open(board, "w") as f:
    json.dump({
        "format": "camhead-board", "version": 1, "name": "soak",
        "lens": {"profile": os.path.join(lenses, "example_35mm.json"),
                 "sources": [{"name": "focus pull", "type": "trace", "loop": True,
                              "file": os.path.join(lenses, "sim_focus_pull.csv")}]},
        "camera": {"type": "sim", "width": 96, "height": 72, "fps": FPS, "samples": 2},
        "scene": os.path.join(args.source, "scenes", "sim_rig.json"),
        "outputs": ["null"],
        "render": {"executor": "cpu", "min_rays_per_pixel": 1, "max_rays_per_pixel": 4}}, f)


def status_field(pid, name):
    """A number from /proc/PID/status ("VmRSS" in KiB, "Threads")."""
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith(name + ":"):
                return int(line.split()[1])
    raise RuntimeError("no %s in /proc/%d/status" % (name, pid))


def rss_kib(pid):
    return status_field(pid, "VmRSS")


def threads(pid):
    return status_field(pid, "Threads")


def descriptors(pid):
    return len(os.listdir("/proc/%d/fd" % pid))


run = subprocess.Popen([args.camhead, "run", "--board", board, "--record-stats", stats,
                        "--threads", "1"], stderr=subprocess.PIPE, text=True)
start = time.monotonic()
warm_up = max(10.0, args.seconds / 4)
samples = []  # (seconds since start, rss KiB)
at_warm = None  # (CLOCK_MONOTONIC ns, descriptors, threads)
try:
    while time.monotonic() - start < args.seconds:
        time.sleep(1.0)
        if run.poll() is not None:
            break
        now = time.monotonic() - start
        samples.append((now, rss_kib(run.pid)))
        if at_warm is None and now >= warm_up:
            at_warm = (time.clock_gettime_ns(time.CLOCK_MONOTONIC), descriptors(run.pid),
                       threads(run.pid))
    alive = run.poll() is None
    at_end = (time.clock_gettime_ns(time.CLOCK_MONOTONIC), descriptors(run.pid),
              threads(run.pid)) if alive else None
finally:
    if run.poll() is None:
        run.send_signal(signal.SIGTERM)
_, stderr = run.communicate(timeout=120)

failures = []
if not alive or at_warm is None:
    print(stderr)
    print("FAIL camhead ended after %.0f s (exit %s)" % (time.monotonic() - start, run.returncode))
    sys.exit(1)
if run.returncode != 0:
    failures.append("exit status %d" % run.returncode)

after = [kib for t, kib in samples if warm_up <= t < warm_up + 10]
last = [kib for t, kib in samples if t >= samples[-1][0] - 10]
growth_kib = statistics.median(last) - statistics.median(after)
frames = 0
with open(stats) as f:
    for line in f:
        record = json.loads(line)
        if at_warm[0] <= record["output_ns"] < at_end[0]:
            frames += 1
expected = FPS * (at_end[0] - at_warm[0]) / 1e9
figures = {
    "seconds": round(samples[-1][0], 1),
    "warm_up_s": warm_up,
    "rss_after_warm_up_kib": statistics.median(after),
    "rss_growth_kib": growth_kib,
    "rss_peak_kib": max(kib for _, kib in samples),
    "descriptors": [at_warm[1], at_end[1]],
    "threads": [at_warm[2], at_end[2]],
    "frames_out": frames,
    "frames_expected": round(expected, 1),
    "frames_error_percent": round(100.0 * (frames - expected) / expected, 4),
}
for key, value in figures.items():
    print("%s: %s" % (key, value))
print(stderr.strip().splitlines()[-2] if stderr.strip() else "(no summary)")
if growth_kib >= 1024:
    failures.append("memory grew %d KiB after warm-up" % growth_kib)
if at_warm[1] != at_end[1]:
    failures.append("descriptors %d -> %d" % (at_warm[1], at_end[1]))
if at_warm[2] != at_end[2]:
    failures.append("threads %d -> %d" % (at_warm[2], at_end[2]))
if abs(frames - expected) > 0.001 * expected:
    failures.append("%d frames out, %.1f expected" % (frames, expected))
if args.json:
    with open(args.json, "w") as f:
        json.dump(figures, f, indent=1)
print("FAIL " + "; ".join(failures) if failures else "PASS")
sys.exit(1 if failures else 0)
