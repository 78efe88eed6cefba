#!/usr/bin/env python3
"""The hardware lab's eyes: screendumps of the guest's display, on request.

run_lab.sh starts this next to QEMU. The guest's check (drm_vm_check.cpp)
writes requests to its /dev/ttyS1, which QEMU connects to the socket
--control; each request is answered on the same port after a `screendump`
through the QEMU monitor's socket (--monitor), with a verdict on the picture:

    HELLO TAG                               -> HELLO TAG
    DUMP NAME WxH console                   -> NAME PASS|FAIL detail
    DUMP NAME WxH grey FWxFH+X+Y V          -> ...
    DUMP NAME WxH pattern FWxFH+X+Y SEED    -> ...
    DUMP NAME WxH same OTHER                -> ...

WxH is the screen size the guest set. `grey` and `pattern` expect black
everywhere but the frame area FWxFH at (X, Y), which holds grey V or test
pattern SEED (pattern_row() below, the formula of drm_vm_check.cpp's
pattern()); `same` expects the very pixels of an earlier dump; `console`
expects a text console (some pixels lit, not one colour). Comparisons are
exact: PPM holds the guest's XRGB8888 as RGB bytes (Debian's QEMU 7.2 swaps
red and blue in PNG dumps, not in PPM). Dumps stay in --out-dir as NAME.ppm.

Only the Python standard library: python3 comes with clang-format on Debian.
Exits when QEMU closes the sockets (the guest powered off).
"""
import argparse
import os
import socket
import sys
import time


def connect(path, deadline):
    """QEMU makes its server sockets at start-up: retry until then."""
    while True:
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            sock.connect(path)
            return sock
        except (FileNotFoundError, ConnectionRefusedError):
            sock.close()
            if time.monotonic() > deadline:
                raise
            time.sleep(0.05)


class Monitor:
    """The human monitor (HMP): a command, then everything up to the next prompt."""

    PROMPT = b"(qemu) "

    def __init__(self, sock):
        self.sock = sock
        self.pending = b""
        self.until_prompt()  # the banner

    def until_prompt(self):
        while self.PROMPT not in self.pending:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise EOFError("the QEMU monitor closed")
            self.pending += chunk
        text, _, self.pending = self.pending.partition(self.PROMPT)
        return text.decode(errors="replace")

    def command(self, line):
        self.sock.sendall(line.encode() + b"\n")
        # The monitor echoes the line (with terminal escapes); what it
        # printed besides is in the text too, for errors.
        return self.until_prompt()


def read_ppm(path):
    with open(path, "rb") as f:
        data = f.read()
    fields, at = [], 0
    while len(fields) < 4:
        while data[at:at + 1].isspace():
            at += 1
        start = at
        while not data[at:at + 1].isspace():
            at += 1
        fields.append(data[start:at])
    if fields[0] != b"P6" or fields[3] != b"255":
        raise ValueError(f"{path}: not an 8-bit binary PPM")
    width, height = int(fields[1]), int(fields[2])
    pixels = data[at + 1:]
    if len(pixels) != width * height * 3:
        raise ValueError(f"{path}: {len(pixels)} bytes of pixels for {width}x{height}")
    return width, height, pixels


def pattern_row(y, width, seed):
    """Row y of test pattern `seed`, RGB; drm_vm_check.cpp's pattern()."""
    row = bytearray(width * 3)
    row[0::3] = bytes((x * 3 + seed * 50) & 255 for x in range(width))
    row[1::3] = bytes([(y * 5 + seed * 30) & 255]) * width
    row[2::3] = bytes((x + y + (x >> 8) * 37 + (y >> 8) * 59 + seed * 70) & 255
                      for x in range(width))
    return bytes(row)


def first_difference(got, want, width, row_index):
    for i in range(0, len(want), 3):
        if got[i:i + 3] != want[i:i + 3]:
            return (f"pixel ({i // 3}, {row_index}) is {tuple(got[i:i + 3])}, "
                    f"want {tuple(want[i:i + 3])}")
    return "rows differ"  # not reached


def compare_rows(pixels, width, height, expected_row):
    """expected_row(y) gives row y's RGB bytes; the verdict and its detail."""
    stride = width * 3
    wrong_rows, first = 0, ""
    for y in range(height):
        want = expected_row(y)
        got = pixels[y * stride:(y + 1) * stride]
        if got != want:
            if not first:
                first = first_difference(got, want, width, y)
            wrong_rows += 1
    if wrong_rows:
        return False, f"{wrong_rows} of {height} rows differ; first: {first}"
    return True, "every pixel as expected"


def framed(width, x, fw, inner):
    """A screen row: black, `inner` (fw pixels) at x, black."""
    return bytes(x * 3) + inner + bytes((width - x - fw) * 3)


def parse_rect(text):
    size, x, y = text.split("+")
    fw, fh = size.split("x")
    return int(fw), int(fh), int(x), int(y)


def judge(kind, args, width, height, pixels, dumps):
    if kind == "console":
        lit = sum(1 for i in range(0, len(pixels), 3) if pixels[i:i + 3] != b"\0\0\0")
        if lit == 0:
            return False, "the screen is all black, not a text console"
        if pixels == pixels[:3] * (width * height):
            return False, f"the screen is one colour {tuple(pixels[:3])}, not a text console"
        return True, f"a text console ({lit} pixels lit)"
    if kind in ("grey", "pattern"):
        fw, fh, x, y = parse_rect(args[0])
        value = int(args[1])
        black = bytes(width * 3)
        if kind == "grey":
            inner = bytes([value]) * (fw * 3)
            row = framed(width, x, fw, inner)
            ok, detail = compare_rows(pixels, width, height,
                                      lambda r: row if y <= r < y + fh else black)
            what = f"grey {value} in {args[0]}, black around"
        else:
            ok, detail = compare_rows(
                pixels, width, height,
                lambda r: framed(width, x, fw, pattern_row(r - y, fw, value))
                if y <= r < y + fh else black)
            what = f"pattern {value} in {args[0]}, black around"
        return ok, f"{what}: {detail}"
    if kind == "same":
        other = dumps.get(args[0])
        if other is None:
            return False, f"no earlier dump {args[0]}"
        if other[:2] != (width, height):
            return False, f"{args[0]} was {other[0]}x{other[1]}, this is {width}x{height}"
        ok, detail = compare_rows(pixels, width, height,
                                  lambda r: other[2][r * width * 3:(r + 1) * width * 3])
        return ok, f"the same as {args[0]}: {detail}"
    return False, f"unknown kind {kind}"


def dump(monitor, out_dir, words, dumps):
    name, size, kind, args = words[1], words[2], words[3], words[4:]
    path = os.path.join(out_dir, name + ".ppm")
    if os.path.exists(path):
        os.remove(path)
    said = monitor.command(f"screendump {path}")
    # The prompt comes back once the file is written; a short grace period
    # all the same, in case a terminal redraw printed an early prompt.
    deadline = time.monotonic() + 5
    while True:
        try:
            width, height, pixels = read_ppm(path)
            break
        except (OSError, ValueError, IndexError) as error:
            if time.monotonic() > deadline:
                return False, f"screendump {path}: {error}; the monitor said {said.strip()!r}"
            time.sleep(0.05)
    dumps[name] = (width, height, pixels)
    want_w, want_h = (int(v) for v in size.split("x"))
    if (width, height) != (want_w, want_h):
        return False, f"the screen is {width}x{height}, not {size}"
    return judge(kind, args, width, height, pixels, dumps)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--monitor", required=True)
    parser.add_argument("--control", required=True)
    parser.add_argument("--out-dir", required=True)
    options = parser.parse_args()
    os.makedirs(options.out_dir, exist_ok=True)
    deadline = time.monotonic() + 60
    monitor = Monitor(connect(options.monitor, deadline))
    control = connect(options.control, deadline)
    dumps, pending = {}, b""
    while True:
        chunk = control.recv(4096)
        if not chunk:
            return 0
        pending += chunk
        while b"\n" in pending:
            line, _, pending = pending.partition(b"\n")
            words = line.decode(errors="replace").strip().split()
            if not words:
                continue
            if words[0] == "HELLO":
                reply = " ".join(words)
            elif words[0] == "DUMP" and len(words) >= 4:
                try:
                    ok, detail = dump(monitor, options.out_dir, words, dumps)
                except (OSError, ValueError) as error:
                    ok, detail = False, f"screendump {words[1]}: {error}"
                reply = f"{words[1]} {'PASS' if ok else 'FAIL'} {detail}"
            else:
                reply = f"{words[0]} FAIL cannot parse {line!r}"
            print(reply, flush=True)
            control.sendall(reply.encode() + b"\n")


if __name__ == "__main__":
    try:
        sys.exit(main())
    except (EOFError, ConnectionError) as error:
        # QEMU went away mid-request: the guest is gone too.
        print(f"screen_helper: {error}", file=sys.stderr)
        sys.exit(0)
