#!/usr/bin/env python3
"""Latency per stage of `camhead run --record-stats FILE.jsonl`.

Prints the median and 99th percentile (ms) of, per composite frame:
  camera    capture (start of exposure) -> the camera hands the frame over
  queued    handed over -> the renderer is free (the previous frame done):
            the newest frame's age when a busy renderer takes it
  handoff   the renderer free (or the frame there, whichever is later) ->
            rendering starts: queue wake-up, slot, lens lookup
  render    the frame renderer (decode, trace, encode)
  output    rendering done -> every output has it
  total     capture -> output
  overhead  handoff + output: the pipeline's own cost beyond rendering
and the output rate, the rays per pixel and the drops.

    bench/pipeline_latency.py stats.jsonl [--skip N]
"""
import argparse
import json
import statistics
import sys


def percentile(values, q):
    s = sorted(values)
    if not s:
        return float("nan")
    k = min(len(s) - 1, max(0, int(round(q * (len(s) - 1)))))
    return s[k]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("stats")
    ap.add_argument("--skip", type=int, default=2, help="first composites to leave out (warm-up)")
    args = ap.parse_args()
    records, fillers = [], 0
    with open(args.stats) as f:
        for n, line in enumerate(f, 1):
            r = json.loads(line)
            if r.get("kind") == "composite":
                records.append(r)
            else:
                fillers += 1
    # The previous composite's render end, for the time a frame waited for a
    # busy renderer (only the composite before it in the record can be it).
    for prev, r in zip(records, records[1:]):
        r["free_ns"] = max(r["delivered_ns"], prev["render_end_ns"])
    records = records[max(args.skip, 1):]
    if len(records) < 2:
        sys.exit(f"{args.stats}: fewer than 2 composites after --skip {args.skip}")
    ms = lambda a, b: [(r[b] - r[a]) * 1e-6 for r in records]
    stages = {
        "camera": ms("capture_ns", "delivered_ns"),
        "queued": ms("delivered_ns", "free_ns"),
        "handoff": ms("free_ns", "render_start_ns"),
        "render": ms("render_start_ns", "render_end_ns"),
        "output": ms("render_end_ns", "output_ns"),
        "total": ms("capture_ns", "output_ns"),
    }
    stages["overhead"] = [h + o for h, o in zip(stages["handoff"], stages["output"])]
    print(f"{len(records)} composites ({fillers} repeats/placeholders), executor: {records[0]['executor']}")
    print(f"{'stage':10s} {'median ms':>10s} {'p99 ms':>10s}")
    for name, values in stages.items():
        print(f"{name:10s} {statistics.median(values):10.2f} {percentile(values, 0.99):10.2f}")
    span_s = (records[-1]["output_ns"] - records[0]["output_ns"]) * 1e-9
    fps = (len(records) - 1) / span_s if span_s > 0 else float("nan")
    rpp = statistics.median(r["rpp"] for r in records)
    dropped = sum(r["dropped_before"] for r in records)
    print(f"output {fps:.2f} fps, median rpp {rpp:g}, camera frames not output: {dropped}")


if __name__ == "__main__":
    main()
