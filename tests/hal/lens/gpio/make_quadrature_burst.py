#!/usr/bin/env python3
"""Writes the recorded quadrature burst that tests/hal/lens/gpio/recording_test.cpp
replays: a 1 MHz-equivalent edge stream (focus edges 1 us apart) of 3.7 ms.

    python3 tests/hal/lens/gpio/make_quadrature_burst.py > tests/assets/quadrature_burst_1mhz.csv

It is written step by step, independently of camhead's C++ twin (which makes
the same stream from a trajectory; the test checks the two agree), and its
expected counts come from the plan below, not from any decoder:

  focus: +2000, -1200, +500 counts, one edge per microsecond (true end: 1300).
         Six merged pairs: edge k is stamped with edge k+1's time, so A and B
         change in one tick and a decoder must count a missed edge and lose
         those two steps: 4 pairs going up (-8), 2 going down (+4), so the
         decoded end is 1300 - 8 + 4 = 1296 with 6 missed edges. Two edges are
         reported twice 100 ns apart (same level twice: 2 duplicates, no
         effect) and two bounce (the line flips back and forth 100 and 200 ns
         after the edge: no net effect).
  zoom:  -40, +15 counts, one edge per 20 us, offset by 0.25 us so no zoom
         edge shares a focus timestamp (true end: -25, nothing missed).

Both axes start at count 0 with A = B = 0. Format: '#' comment lines, a
header line, then one edge per line: t_ns,axis,line,level with line a or b.
"""
import sys

# AB by count mod 4: counting up is A leading B.
GRAY = [(0, 0), (1, 0), (1, 1), (0, 1)]

FOCUS_PHASES = [(+1, 2000), (-1, 1200), (+1, 500)]
FOCUS_MERGED = [500, 1000, 1500, 2300, 2700, 3500]
FOCUS_DUPLICATED = [100, 2500]
FOCUS_BOUNCED = [200, 3000]
BOUNCE_NS = 100
ZOOM_PHASES = [(-1, 40), (+1, 15)]


def steps(phases):
    """(direction of each step, in order)."""
    return [d for d, n in phases for _ in range(n)]


def edges(axis, directions, first_ns, period_ns):
    """One edge per step: [t_ns, axis, line, level]."""
    out, count, t = [], 0, first_ns
    for d in directions:
        (a0, b0), (a1, b1) = GRAY[count % 4], GRAY[(count + d) % 4]
        out.append([t, axis, "a", a1] if a0 != a1 else [t, axis, "b", b1])
        count += d
        t += period_ns
    return out, count


def with_faults(clean, merged, duplicated, bounced):
    out = []
    for k, (t, axis, line, level) in enumerate(clean):
        if k in merged:
            t = clean[k + 1][0]
        out.append([t, axis, line, level])
        if k in duplicated:
            out.append([t + BOUNCE_NS, axis, line, level])
        if k in bounced:
            out.append([t + BOUNCE_NS, axis, line, 1 - level])
            out.append([t + 2 * BOUNCE_NS, axis, line, level])
    return sorted(out, key=lambda e: e[0])  # stable


def main():
    focus_dirs = steps(FOCUS_PHASES)
    for k in FOCUS_MERGED:  # each merged pair lies inside one phase
        assert focus_dirs[k] == focus_dirs[k + 1]
    focus_clean, focus_true = edges("focus", focus_dirs, 1000, 1000)
    zoom_clean, zoom_true = edges("zoom", steps(ZOOM_PHASES), 10250, 20000)
    focus_expect = focus_true - sum(2 * focus_dirs[k] for k in FOCUS_MERGED)

    events = with_faults(focus_clean, FOCUS_MERGED, FOCUS_DUPLICATED, FOCUS_BOUNCED)
    events = sorted(events + zoom_clean, key=lambda e: e[0])

    w = sys.stdout.write
    w("# camhead quadrature edge recording, format 1\n")
    w("# made by tests/hal/lens/gpio/make_quadrature_burst.py (the plan is in its docstring);\n")
    w("# regenerate: python3 tests/hal/lens/gpio/make_quadrature_burst.py "
      "> tests/assets/quadrature_burst_1mhz.csv\n")
    w(f"# expect focus_count={focus_expect} focus_missed={len(FOCUS_MERGED)} "
      f"focus_duplicates={len(FOCUS_DUPLICATED)} zoom_count={zoom_true} zoom_missed=0 "
      f"events={len(events)}\n")
    w("t_ns,axis,line,level\n")
    for t, axis, line, level in events:
        w(f"{t},{axis},{line},{level}\n")


if __name__ == "__main__":
    main()
