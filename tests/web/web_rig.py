"""The simulated rig with its operator page on, for the web tests.

A small simulated camera (the sim rig's scene, lens profile and looped
focus pull) so that 25 fps hold beside other tests; the page on a port the
kernel picks, read from camhead's "operator page at URL" line.
"""
import base64
import http.client
import json
import os
import re
import subprocess
import sys
import time
import urllib.parse


def write_board(scratch, source, name="web", width=192, height=144, http=None):
    lenses = os.path.join(source, "scenes", "lenses")
    board = {
        "format": "camhead-board", "version": 1, "name": name,
        "lens": {"profile": os.path.join(lenses, "example_35mm.json"),
                 "sources": [{"name": "focus pull", "type": "trace", "loop": True,
                              "file": os.path.join(lenses, "sim_focus_pull.csv")}]},
        "camera": {"type": "sim", "width": width, "height": height, "fps": 25, "samples": 2},
        "scene": os.path.join(source, "scenes", "sim_rig.json"),
        "outputs": ["null"],
        "render": {"executor": "cpu", "min_rays_per_pixel": 1, "max_rays_per_pixel": 4}}
    if http is not None:
        board["http"] = http
    path = os.path.join(scratch, name + "_board.json")
    with open(path, "w") as f:
        json.dump(board, f)
    return path


class Run:
    """`camhead run` with its page; stopped (SIGINT) on exit.

    Give it no --duration: a run that ended on the clock while a loaded
    machine was still working through the steps would fail them."""

    def __init__(self, camhead, board, *extra, stats=None):
        args = [camhead, "run", "--board", board, "--threads", "1", *extra]
        if stats:
            args += ["--record-stats", stats]
        # In the board's folder: the page's takes go to ./recordings.
        self.process = subprocess.Popen(args, stderr=subprocess.PIPE, text=True,
                                        cwd=os.path.dirname(os.path.abspath(board)))
        self.lines = []
        self.url = None
        deadline = time.monotonic() + 60
        while self.url is None and time.monotonic() < deadline:
            line = self.process.stderr.readline()
            if not line:
                break
            self.lines.append(line)
            found = re.search(r"operator page at (http://\S+)", line)
            if found:
                self.url = found.group(1)
        if self.url is None:
            self.stop()
            raise RuntimeError("camhead printed no page address:\n" + "".join(self.lines))
        parsed = urllib.parse.urlsplit(self.url)
        self.host, self.port = parsed.hostname, parsed.port

    def connection(self, timeout=10):
        return http.client.HTTPConnection(self.host, self.port, timeout=timeout)

    def get(self, path, headers=None, method="GET", body=None):
        """(status, headers, body bytes) of one request on a new connection."""
        c = self.connection()
        c.request(method, path, body=body, headers=headers or {})
        r = c.getresponse()
        data = r.read()
        c.close()
        return r.status, dict(r.getheaders()), data

    def state(self, headers=None):
        status, _, body = self.get("/api/state", headers)
        assert status == 200, status
        return json.loads(body)

    def wait_frames(self, count, headers=None, timeout=60):
        """Until the newest composite went out as output frame `count` or later
        (repeats and placeholders take indices too)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            frame = self.state(headers).get("frame")
            if frame and frame["frame"] >= count:
                return
            time.sleep(0.2)
        raise RuntimeError("the outputs got fewer than %d frames in %d s" % (count, timeout))

    def stop(self):
        if self.process.poll() is None:
            self.process.send_signal(2)
        try:
            _, rest = self.process.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            _, rest = self.process.communicate()
        self.lines.append(rest or "")
        return self.process.returncode

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()


def basic(user, password):
    token = base64.b64encode(("%s:%s" % (user, password)).encode()).decode()
    return {"Authorization": "Basic " + token}


def mjpeg_frames(response, count):
    """`count` (frame number, JPEG bytes) parts of a multipart/x-mixed-replace reply."""
    boundary = response.getheader("Content-Type").split("boundary=")[1].encode()
    parts = []
    while len(parts) < count:
        line = response.readline()
        if not line:
            raise RuntimeError("the stream ended")
        if line.strip() != b"--" + boundary:
            continue
        headers = {}
        while True:
            line = response.readline().strip()
            if not line:
                break
            key, value = line.decode().split(":", 1)
            headers[key.strip().lower()] = value.strip()
        jpeg = response.read(int(headers["content-length"]))
        parts.append((int(headers["x-frame"]), jpeg))
    return parts


def read_stats(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


class Checks:
    """A test's checks: a line each, then PASS or FAIL with what failed."""

    def __init__(self):
        self.failures = []

    def __call__(self, ok, what):
        print(("ok   " if ok else "FAIL ") + what, flush=True)
        if not ok:
            self.failures.append(what)

    def finish(self):
        print("PASS" if not self.failures else "FAIL " + "; ".join(self.failures))
        sys.exit(1 if self.failures else 0)
