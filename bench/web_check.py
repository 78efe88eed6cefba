#!/usr/bin/env python3
"""What the operator page costs `camhead run`, from outside (bench/RESULTS.md,
"The operator page").

    /usr/bin/python3 bench/web_check.py CAMHEAD [--size 360x288] [--phase 20]

One run of the simulated rig (its scene, lens profile and looped focus pull;
the CPU reference, the camera's 25 fps) with the page on, its record
(--record-stats) kept, in phases of PHASE seconds after a warm-up: no
client, one preview client, twenty preview clients and one that never
reads, and no client again. For each phase, from the record: composites
out per second, and the median and 99th percentile of the whole latency
(camera timestamp to the outputs), of the render and of the output stage
(render end to the outputs: where the preview is shrunk); from the page's
/metrics: the JPEG encode time per preview frame; from the one client:
the preview's latency, camera timestamp to the part's arrival.
Run it on a quiet machine; it prints a table in the format of RESULTS.md.
"""
import argparse
import json
import os
import socket
import statistics
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "web"))
import web_rig  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("camhead")
parser.add_argument("--size", default="360x288")
parser.add_argument("--phase", type=float, default=20.0)
parser.add_argument("--warmup", type=float, default=30.0)
args = parser.parse_args()
width, height = (int(x) for x in args.size.split("x"))
source = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
scratch = tempfile.mkdtemp(prefix="camhead_web_check_")
board = web_rig.write_board(scratch, source, name="webcheck", width=width, height=height)
stats = os.path.join(scratch, "stats.jsonl")


def jpeg_totals(run):
    text = run.get("/metrics")[2].decode()
    values = {}
    for line in text.splitlines():
        if line.startswith("camhead_preview_jpeg_seconds_"):
            name, value = line.split()
            values[name] = float(value)
    return values.get("camhead_preview_jpeg_seconds_sum", 0.0), \
        values.get("camhead_preview_jpeg_seconds_count", 0.0)


class Reader(threading.Thread):
    """A preview client; the first one notes each part's arrival."""

    def __init__(self, run, timed):
        super().__init__(daemon=True)
        self.run_, self.timed, self.stop = run, timed, threading.Event()
        self.arrivals = []

    def run(self):
        c = self.run_.connection(timeout=30)
        c.request("GET", "/stream.mjpeg")
        r = c.getresponse()
        while not self.stop.is_set():
            frame, _ = web_rig.mjpeg_frames(r, 1)[0]
            if self.timed:
                self.arrivals.append((frame, time.monotonic_ns()))
        c.close()


phases = []
with web_rig.Run(args.camhead, board, "--http", "127.0.0.1:0", stats=stats) as run:
    time.sleep(args.warmup)
    for name, clients, quiet in (("no client", 0, False), ("1 client", 1, False),
                                 ("20 clients + 1 not reading", 20, True),
                                 ("no client again", 0, False)):
        readers = [Reader(run, i == 0) for i in range(clients)]
        sockets = []
        if quiet:
            s = socket.create_connection((run.host, run.port))
            s.sendall(b"GET /stream.mjpeg HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
            sockets.append(s)
        for r in readers:
            r.start()
        time.sleep(1.0)  # the streams open
        jpeg_before = jpeg_totals(run)
        start = time.monotonic_ns()
        time.sleep(args.phase)
        end = time.monotonic_ns()
        jpeg_after = jpeg_totals(run)
        for r in readers:
            r.stop.set()
        for s in sockets:
            s.close()
        for r in readers:
            r.join(timeout=5)
        phases.append({"name": name, "start": start, "end": end,
                       "jpeg": (jpeg_after[0] - jpeg_before[0], jpeg_after[1] - jpeg_before[1]),
                       "arrivals": readers[0].arrivals if readers else []})

records = [r for r in web_rig.read_stats(stats) if r["kind"] == "composite"]
by_frame = {r["output_frame"]: r for r in records}


def q(values, p):
    values = sorted(values)
    return values[min(len(values) - 1, int(p * len(values)))] if values else float("nan")


print("| phase | fps out | latency median / p99 ms | render median / p99 ms | "
      "output stage median / p99 ms | JPEG ms per frame (frames) | preview latency median / p99 ms |")
print("|---|---|---|---|---|---|---|")
for p in phases:
    rs = [r for r in records if p["start"] <= r["output_ns"] < p["end"]]
    lat = [(r["output_ns"] - r["capture_ns"]) / 1e6 for r in rs]
    render = [(r["render_end_ns"] - r["render_start_ns"]) / 1e6 for r in rs]
    out = [(r["output_ns"] - r["render_end_ns"]) / 1e6 for r in rs]
    fps = len(rs) / ((p["end"] - p["start"]) / 1e9)
    jpeg_s, jpeg_n = p["jpeg"]
    preview = [(t - by_frame[f]["capture_ns"]) / 1e6 for f, t in p["arrivals"] if f in by_frame]
    print("| %s | %.1f | %.1f / %.1f | %.2f / %.2f | %.3f / %.3f | %s | %s |" % (
        p["name"], fps, q(lat, 0.5), q(lat, 0.99), q(render, 0.5), q(render, 0.99),
        q(out, 0.5), q(out, 0.99),
        "%.2f (%d)" % (1e3 * jpeg_s / jpeg_n, jpeg_n) if jpeg_n else "-",
        "%.1f / %.1f" % (q(preview, 0.5), q(preview, 0.99)) if preview else "-"))
print("scratch: " + scratch)
