#!/usr/bin/env python3
"""The operator page of `camhead run` from outside, as a client sees it.

    web_test.py CAMHEAD SOURCE_DIR SCRATCH_DIR

1. State: /api/state's newest frame is a line of --record-stats, value for value.
2. Metrics: /metrics parses with Prometheus's own parser (prometheus_client).
3. Preview: the MJPEG stream's frames decode to the composite: each part
   (its X-Frame) against that frame of the run's Y4M output, shrunk the same
   way, within JPEG's error (PSNR); the region view keeps the frame's
   traced share at full brightness and darkens the rest.
   Record: the record button's take holds the composites the outputs got
   while it was on, byte for byte.
   Mark and reload: a calibration mark as `camhead calibrate` reads it;
   the board reloaded from the page, and a board that changes what only a
   restart may change refused, the outcome in the state.
4. Clients: one that never reads and 20 that do, at once: the outputs get
   every composite (no output-busy drop, no repeat) while they watch, and
   the page still answers.
5. Access: a page on an address other machines reach needs a password
   (refused to start without one, or with a file others can read); without
   it every endpoint answers 401, a wrong one 401 and after five 429 for the
   sender; traversal, oversized headers, bad JSON and a flood are refused
   with the right status and the run goes on.
6. Calibration views: the camera frame's luma saved whole for `calibrate
   camera` in a folder per lens position, checked for the marker board's
   markers where the run has one, and read by the command the reply names.
Prints a line per check, then PASS or FAIL.
"""
import io
import json
import os
import shutil
import socket
import stat
import subprocess
import sys
import threading
import time

import numpy
from PIL import Image
from prometheus_client.parser import text_string_to_metric_families

import web_rig

camhead, source, scratch = sys.argv[1], os.path.abspath(sys.argv[2]), os.path.abspath(sys.argv[3])
# A sanitizer build does not hold the camera's rate: the outputs repeat
# frames with or without clients, so only what the page could cause counts.
sanitized = "--sanitized" in sys.argv[4:]
# The marker module was built: the calibration views are checked for the board.
markers = "--markers" in sys.argv[4:]
os.makedirs(scratch, exist_ok=True)
check = web_rig.Checks()


def y4m_frames(path):
    """Each frame's (Y, Cb, Cr) planes of a 4:2:2 Y4M file, as float arrays."""
    data = open(path, "rb").read()
    header_end = data.index(b"\n")
    fields = data[:header_end].split()
    width = int([f for f in fields if f.startswith(b"W")][0][1:])
    height = int([f for f in fields if f.startswith(b"H")][0][1:])
    assert b"C422" in fields, fields
    frames, at = [], header_end + 1
    size = width * height * 2
    while at < len(data):
        at = data.index(b"\n", at) + 1  # FRAME line
        y = numpy.frombuffer(data, numpy.uint8, width * height, at).reshape(height, width)
        cb = numpy.frombuffer(data, numpy.uint8, width * height // 2, at + width * height)
        cr = numpy.frombuffer(data, numpy.uint8, width * height // 2,
                              at + width * height * 3 // 2)
        frames.append((y.astype(float), cb.reshape(height, width // 2).astype(float),
                       cr.reshape(height, width // 2).astype(float)))
        at += size
    return frames


def preview_of(planes, step):
    """A Y4M frame shrunk by `step` (box) to BT.709 limited-range R'G'B', as camhead shrinks it."""
    y, cb, cr = planes
    h, w = y.shape[0] // step, y.shape[1] // step
    box = lambda p, sx: p[:h * step, :w * sx].reshape(h, step, w, sx).mean(axis=(1, 3))
    l = (box(y, step) - 16) * 255 / 219
    u = (box(cb, step // 2) - 128) * 255 / 224
    v = (box(cr, step // 2) - 128) * 255 / 224
    kr, kb = 0.2126, 0.0722
    r = l + 2 * (1 - kr) * v
    b = l + 2 * (1 - kb) * u
    g = (l - kr * r - kb * b) / (1 - kr - kb)
    return numpy.clip(numpy.stack([r, g, b], axis=-1), 0, 255)


def psnr(a, b):
    mse = numpy.mean((a - b) ** 2)
    return 99.0 if mse == 0 else 10 * numpy.log10(255 ** 2 / mse)


# -- 1 to 4: a loopback page, no password ----------------------------------
# Marks and takes append to what a run before left: start without them.
shutil.rmtree(os.path.join(scratch, "recordings"), ignore_errors=True)
board = web_rig.write_board(scratch, source)
y4m = os.path.join(scratch, "web.y4m")
stats = os.path.join(scratch, "web_stats.jsonl")
with web_rig.Run(camhead, board, "--http", "127.0.0.1:0", "--output", "file:" + y4m,
                 stats=stats) as run:
    run.wait_frames(10)
    state = run.state()
    seen_frame = state["frame"]
    check(state["board"]["name"] == "web" and state["camera"]["connected"] and
          state["in_fps"] > 0 and state["out_fps"] > 0 and
          len(state["outputs"]) == 1 and "capture_to_output" in state["latency"],
          "state: board, camera, outputs, frames in and out per second (%.1f, %.1f), latency "
          "per stage" % (state["in_fps"], state["out_fps"]))

    status, headers, body = run.get("/metrics")
    families = {f.name: f for f in text_string_to_metric_families(body.decode())}
    out = families.get("camhead_frames_out")  # the parser drops _total
    # The count of composites, not of the frames the outputs got: a sanitizer
    # build sends repeats between them, so the state's count read just before
    # is the floor, not the frame index waited for.
    check(status == 200 and out is not None and
          out.samples[0].value >= max(1, state["counts"]["frames_out"]) and
          "camhead_stage_latency_seconds" in families and
          headers.get("Content-Type", "").startswith("text/plain; version=0.0.4"),
          "metrics: parsed by prometheus_client (%d families; %d composites out, the state "
          "said %d)" % (len(families), int(out.samples[0].value) if out else -1,
                        state["counts"]["frames_out"]))

    c = run.connection()
    c.request("GET", "/stream.mjpeg")
    response = c.getresponse()
    parts = web_rig.mjpeg_frames(response, 8)
    c.close()
    check(response.status == 200 and len({n for n, _ in parts}) == 8,
          "preview: 8 distinct frames from /stream.mjpeg")
    c = run.connection()
    c.request("GET", "/stream.mjpeg?view=region")
    response = c.getresponse()
    region_parts = web_rig.mjpeg_frames(response, 8)
    c.close()

    as_json = {"Content-Type": "application/json"}
    started = run.get("/api/record", as_json, method="POST", body='{"recording": true}')
    again = run.get("/api/record", as_json, method="POST", body='{"recording": true}')
    time.sleep(2)
    recording = run.state()["recording"]
    stopped = run.get("/api/record", as_json, method="POST", body='{"recording": false}')
    take = json.loads(stopped[2]) if stopped[0] == 200 else {}
    check(started[0] == 200 and again[0] == 409 and recording and recording["frames"] > 0 and
          stopped[0] == 200 and os.path.exists(take.get("file", "")),
          "record: a take started, a second refused (%d), stopped with %s frames in %s"
          % (again[0], take.get("frames"), take.get("file")))

    taken = subprocess.run([camhead, "run", "--board", board, "--http", "127.0.0.1:%d" % run.port,
                            "--output", "file:" + os.path.join(scratch, "never.y4m"),
                            "--duration", "5"], capture_output=True, text=True, timeout=60)
    check(taken.returncode == 2 and "cannot listen on 127.0.0.1:%d" % run.port in taken.stderr and
          not os.path.exists(os.path.join(scratch, "never.y4m")) and
          not os.path.exists(os.path.join(scratch, "never.y4m.partial")),
          "a port already taken: exit 2, named, no output file left: " +
          (taken.stderr.strip().splitlines() or [""])[-1])

    marks = [run.get("/api/mark", as_json, method="POST", body=body) for body in
             ('{"axis": "focus", "value": 2.5}', '{"axis": "iris", "value": 4}',
              '{"axis": "focal", "value": 35}', '{"axis": "zoom", "value": -1}')]
    focus_mark, iris_mark = (json.loads(m[2]) for m in marks[:2])
    rows = [line.strip().split(",") for line in open(focus_mark.get("file", os.devnull))
            if line[:1].isalpha() and not line.startswith("axis,")]
    check([m[0] for m in marks] == [200, 200, 400, 400] and
          rows == [["focus", str(focus_mark["counts"]), "2.5", "", "", ""],
                   ["iris", str(iris_mark["counts"]), "", "4", "", ""]],
          "mark: focus and iris at the lens's counts, written as camhead calibrate reads them; "
          "a wrong axis or value 400 (%s)" % rows)

    # Reload: the board as it is taken; then one that changes the camera
    # (a restart's business) is refused, named, and the run goes on.
    def reload_outcome(previous):
        deadline = time.time() + 30
        while time.time() < deadline:
            outcome = run.state()["reload"]
            if outcome["outcomes"] > previous:
                return outcome
            time.sleep(0.2)
        return outcome
    asked = run.get("/api/reload", as_json, method="POST", body="{}")
    taken_reload = reload_outcome(0)
    run.wait_frames(run.state()["frame"]["frame"] + 3)
    setup = run.state()["frame"]["setup"]
    with open(board) as f:
        changed = json.load(f)
    changed["camera"]["width"] = 320
    with open(board, "w") as f:
        json.dump(changed, f)
    run.get("/api/reload", as_json, method="POST", body="{}")
    refused_reload = reload_outcome(1)
    run.wait_frames(run.state()["frame"]["frame"] + 5)
    web_rig.write_board(scratch, source)  # as it was, for what follows
    check(asked[0] == 202 and taken_reload["last"] == "reloaded %s: setup 1" % board and
          setup == 1 and refused_reload["last"].startswith("reload refused") and
          "camera" in refused_reload["last"] and run.state()["frame"]["setup"] == 1,
          "reload: taken (setup %s: %s), a camera change refused and the run goes on: %s"
          % (setup, taken_reload["last"], refused_reload["last"]))

    # A page of another site in this machine's browser: a form's POST, and
    # a name of that site resolving here (DNS rebinding).
    form = run.get("/api/freeze", {"Content-Type": "text/plain"}, method="POST",
                   body='{"frozen": true}')
    rebound = run.get("/api/state", {"Host": "attacker.example:%d" % run.port})
    check(form[0] == 415 and rebound[0] == 403 and not run.state()["frozen"],
          "access: a form's POST refused (%d), a foreign Host refused (%d)"
          % (form[0], rebound[0]))

    # 4. Twenty clients that read and one that never does.
    quiet = socket.create_connection((run.host, run.port))
    quiet.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    quiet.sendall(b"GET /stream.mjpeg HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    stop_readers = threading.Event()
    received = [0] * 20

    def reader(i):
        rc = run.connection(timeout=20)
        rc.request("GET", "/stream.mjpeg")
        rr = rc.getresponse()
        while not stop_readers.is_set():
            web_rig.mjpeg_frames(rr, 1)
            received[i] += 1
        rc.close()

    before = run.state()
    readers = [threading.Thread(target=reader, args=(i,)) for i in range(20)]
    for t in readers:
        t.start()
    time.sleep(8)
    during = run.state()
    stop_readers.set()
    for t in readers:
        t.join()
    quiet.close()
    watched = during["counts"]["frames_out"] - before["counts"]["frames_out"]
    check(during["http"]["stream_clients"] >= 21 and min(received) > 0,
          "clients: 21 streams open, each reader got frames (fewest %d)" % min(received))
    check(during["counts"]["output_busy"] == before["counts"]["output_busy"] and
          (sanitized or during["counts"]["repeats"] == before["counts"]["repeats"]) and
          watched > 0,
          "clients: %d composites out while they watched, no output-busy drop, no repeat"
          % watched)
check(run.process.returncode == 0, "the run ended as asked (exit %s)" % run.process.returncode)
records = [r for r in web_rig.read_stats(stats) if r["kind"] == "composite"]
by_frame = {r["output_frame"]: r for r in records}
r = by_frame.get(seen_frame["frame"])
check(r is not None and all(abs(r[k] - seen_frame[k]) <= 1e-5 * max(1.0, abs(r[k]))
                            for k in ("focus_m", "f_number", "focal_length_mm")) and
      r["sequence"] == seen_frame["sequence"],
      "state: frame %d's lens is the record's (focus %.4f m, f/%.3f)"
      % (seen_frame["frame"], seen_frame["focus_m"], seen_frame["f_number"]))
frames = y4m_frames(y4m)
worst = 99.0
for number, jpeg in parts:
    image = numpy.asarray(Image.open(io.BytesIO(jpeg)).convert("RGB"), dtype=float)
    step = frames[number][0].shape[1] // image.shape[1]
    worst = min(worst, psnr(image, preview_of(frames[number], step)))
other = parts[0][0] + 50
wrong = psnr(numpy.asarray(Image.open(io.BytesIO(parts[0][1])).convert("RGB"), dtype=float),
             preview_of(frames[min(other, len(frames) - 1)], step))
take_frames = y4m_frames(take["file"]) if take.get("file") else []
same = lambda a, b: all((p == q).all() for p, q in zip(a, b))
# Where in the output the take starts: the offset at which every frame of
# it is the output's (a still lens can give equal frames, so not the first
# equal one alone).
first = next((i for i in range(len(frames) - len(take_frames) + 1) if take_frames and
              all(same(frames[i + k], t) for k, t in enumerate(take_frames))), None)
check(len(take_frames) == take.get("frames") and first is not None,
      "record: the take's %d frames (%s said) are the output's frames %s.. byte for byte"
      % (len(take_frames), take.get("frames"), first))
check(worst >= 32.0, "preview: each JPEG is its Y4M frame within JPEG's error "
      "(worst PSNR %.1f dB; a frame 50 later: %.1f dB)" % (worst, wrong))
# The region view is its frame where the renderer traced, a third of it
# elsewhere: the share of the frame at full brightness is the record's
# traced share, less a rim inside the region's edges that JPEG's ringing
# darkens (about 0.04 of the frame here).
shares = []
for number, jpeg in region_parts:
    image = numpy.asarray(Image.open(io.BytesIO(jpeg)).convert("L"), dtype=float)
    step = frames[number][0].shape[1] // image.shape[1]
    full = preview_of(frames[number], step).mean(axis=-1)
    lit = full > 30  # where a third is told apart from the whole through JPEG
    kept = numpy.abs(image - full) < numpy.abs(image - full / 3)
    shares.append((kept[lit].mean(), by_frame[number]["traced"]))
check(len(shares) == 8 and all(abs(shown - traced) <= 0.08 for shown, traced in shares) and
      min(traced for _, traced in shares) < 0.9,
      "preview: the region view keeps the traced share of its frames (shown, traced: %s)"
      % ", ".join("%.2f, %.2f" % s for s in shares))

# -- 5: access ----------------------------------------------------------------
password_file = os.path.join(scratch, "web-password")
if os.path.exists(password_file):
    os.unlink(password_file)
setter = subprocess.run([camhead, "web-password", password_file], input="correct horse\n",
                        text=True, capture_output=True)
check(setter.returncode == 0 and stat.S_IMODE(os.stat(password_file).st_mode) == 0o600,
      "web-password: the hash written with mode 0600")
short = subprocess.run([camhead, "web-password", os.path.join(scratch, "short")], input="abc\n",
                       text=True, capture_output=True)
check(short.returncode == 2 and not os.path.exists(os.path.join(scratch, "short")),
      "web-password: a short password refused, nothing written")

no_password = subprocess.run([camhead, "run", "--board", board, "--http", "0.0.0.0:0",
                              "--duration", "5"], capture_output=True, text=True, timeout=60)
check(no_password.returncode == 2 and "needs a password" in no_password.stderr,
      "access: 0.0.0.0 without a password refused to start: " +
      no_password.stderr.strip().splitlines()[-1])
open_file = os.path.join(scratch, "open-password")
with open(open_file, "w") as f:
    f.write(open(password_file).read())
os.chmod(open_file, 0o644)
readable = subprocess.run([camhead, "run", "--board", board, "--http", "0.0.0.0:0",
                           "--http-password", open_file, "--duration", "5"],
                          capture_output=True, text=True, timeout=60)
check(readable.returncode == 2 and "chmod 600" in readable.stderr,
      "access: a password file others can read refused")

good = web_rig.basic("operator", "correct horse")
bad = web_rig.basic("operator", "wrong horse")
with web_rig.Run(camhead, board, "--http", "0.0.0.0:0", "--http-password", password_file) as run:
    run.host = "127.0.0.1"
    endpoints = ["/", "/app.js", "/api/state", "/api/history", "/api/events", "/metrics",
                 "/stream.mjpeg", "/snapshot.jpg", "/nothing"]
    codes = {path: run.get(path)[0] for path in endpoints}
    codes["POST /api/freeze"] = run.get("/api/freeze", method="POST", body="{}")[0]
    check(set(codes.values()) == {401}, "access: every endpoint 401 without the password %s"
          % sorted(set(codes.values())))
    run.wait_frames(5, good)
    check(run.get("/", good)[0] == 200 and run.get("/metrics", good)[0] == 200,
          "access: the password opens the page")
    traversal = [run.get(p, good)[0] for p in
                 ["/../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/..%2f..%2fetc%2fpasswd",
                  "//etc/passwd", "/index.html/../../../etc/passwd"]]
    check(all(code in (400, 404) for code in traversal),
          "access: traversal refused %s" % traversal)
    big = socket.create_connection((run.host, run.port), timeout=10)
    big.sendall(b"GET /api/state HTTP/1.1\r\nHost: x\r\nX-Big: " + b"a" * 20000 + b"\r\n\r\n")
    answer = big.recv(200)
    big.close()
    check(answer == b"" or answer.split(b" ")[1] in (b"400", b"413", b"431"),
          "access: a 20 kB header refused (%r)" % answer[:30])
    good_json = dict(good, **{"Content-Type": "application/json"})
    bad_json = run.get("/api/freeze", good_json, method="POST", body="{not json")
    bad_field = run.get("/api/freeze", good_json, method="POST", body='{"frozen": "yes"}')
    unknown = run.get("/api/format_disk", good_json, method="POST", body="{}")
    check(bad_json[0] == 400 and bad_field[0] == 400 and unknown[0] == 404,
          "access: bad JSON 400, a wrong field 400, an unknown action 404")
    # libevent answers a method the server does not take with 501.
    put = run.get("/api/state", good, method="PUT", body="{}")
    check(put[0] in (405, 501), "access: PUT refused (%d)" % put[0])
    before = run.state(good)["counts"]["frames_out"]
    start = time.monotonic()
    flood_codes = set()
    for _ in range(300):
        flood_codes.add(run.get("/api/state", good)[0])
    flood_s = time.monotonic() - start
    time.sleep(1)
    after = run.state(good)["counts"]["frames_out"]
    check(flood_codes == {200} and after > before,
          "access: 300 requests in %.1f s answered, the run went on (%d composites)"
          % (flood_s, after - before))
    wrong = [run.get("/api/state", bad)[0] for _ in range(7)]
    locked = run.get("/api/state", good)
    check(wrong[:5] == [401] * 5 and 429 in wrong[5:] and locked[0] == 429 and
          "Retry-After" in locked[1],
          "access: wrong passwords 401, then 429 with Retry-After for the sender %s" % wrong)
    time.sleep(int(locked[1].get("Retry-After", "0")) + 0.2)
    reopened = run.get("/metrics", good)
    check(reopened[0] == 200, "access: the sender is heard again after Retry-After (%d)"
          % reopened[0])
    refused = {s.labels["reason"]: s.value for s in next(
        f for f in text_string_to_metric_families(reopened[2].decode())
        if f.name == "camhead_http_refused").samples}
    check(refused["wrong_credentials"] >= 7 and refused["no_credentials"] >= len(codes),
          "access: the refusals counted %s" % refused)

# -- 6: calibration views ------------------------------------------------------
# The loopback rig has no marker board: a view is saved unchecked.
with web_rig.Run(camhead, board, "--http", "127.0.0.1:0") as run:
    run.wait_frames(3)
    status, _, body = run.get("/api/view", {"Content-Type": "application/json"}, method="POST",
                              body="{}")
    view = json.loads(body)
    picture = Image.open(view["file"]) if status == 200 else None
    check(status == 200 and picture.mode == "L" and picture.size == (192, 144) and
          "no marker board" in view.get("unchecked", "") and
          ("--profile " + os.path.join(source, "scenes", "lenses", "example_35mm.json")) in
          view["command"],
          "view: the camera frame's luma saved whole (%s), unchecked without a marker board: %s"
          % (picture and picture.size, view))

if markers:
    # A moving camera over the printed ChArUco board, the lens held still:
    # each view is checked for the board's markers, all go into the folder
    # of that lens position, and `calibrate camera` reads them.
    trace = os.path.join(scratch, "still_lens.csv")
    with open(trace, "w") as f:
        f.write("# camhead lens trace v1\nt_s,focus,iris,zoom\n")
        f.writelines("%.2f,8000,1900,0\n" % (i / 100) for i in range(6000))
    profile = os.path.join(scratch, "views_profile.json")
    shutil.copy(os.path.join(source, "scenes", "lenses", "example_35mm.json"), profile)
    with open(os.path.join(source, "board", "sim-moving.json")) as f:
        moving = json.load(f)
    scenes = os.path.join(source, "scenes")
    moving.update(
        lens={"profile": profile, "sources": [{"name": "still", "type": "trace", "file": trace}]},
        scene=os.path.join(scenes, "sim_tracked.json"), outputs=["null"],
        pose={"type": "marker", "board": os.path.join(scenes, "markers", "floor_board.json")},
        render={"executor": "cpu", "min_rays_per_pixel": 1, "max_rays_per_pixel": 4})
    # Two rays a pixel, not the board's eight: the views only need their
    # markers read.
    moving["camera"].update(width=360, height=288, samples=2,
                            path=os.path.join(scenes, "paths", "sim_dolly.csv"))
    moving_board = os.path.join(scratch, "views_board.json")
    with open(moving_board, "w") as f:
        json.dump(moving, f)
    shutil.rmtree(os.path.join(scratch, "recordings", "camera-views"), ignore_errors=True)
    views = []
    with web_rig.Run(camhead, moving_board, "--http", "127.0.0.1:0") as run:
        run.wait_frames(2)
        for _ in range(6):
            # 503: no camera frame came within its wait (a sanitizer build
            # beside other tests renders a frame or two a second): again.
            for _ in range(3):
                status, _, body = run.get("/api/view", {"Content-Type": "application/json"},
                                          method="POST", body="{}")
                if status != 503:
                    break
            views.append(json.loads(body) if status == 200 else {"status": status,
                                                                 "reply": body.decode()})
            time.sleep(0.6)
        # The state says how the newest composite's pose was found: the
        # board, sharp at this lens, by its markers (or null, held); found
        # in the views above, it is known (before, the composites were the
        # camera image alone).
        pose = run.state()["pose"]
        check(pose.get("found_by") == ("markers" if pose.get("fresh") else None) and
              pose.get("known") is True,
              "state: the marker pose is known and says how it was found: %s"
              % {k: pose.get(k) for k in ("source", "known", "fresh", "found_by", "markers_seen")})
    folder = os.path.join(scratch, "recordings", "camera-views", "focus-8000")
    seen = [v.get("markers_seen") for v in views]
    check([os.path.basename(v.get("file", "")) for v in views] ==
          ["view-%03d.png" % n for n in range(1, 7)] and
          all(os.path.dirname(v["file"]) == folder and v["markers"] == 17 and
              v["at"] == "focus=8000" for v in views) and max(seen) >= 2,
          "view: six views in the folder of the lens's position, markers seen of 17: %s%s"
          % (seen, "".join("; %s" % v for v in views if "status" in v)))
    command = views[-1]["command"].split()
    fit = subprocess.run([camhead] + command[1:3] + sorted(
        os.path.join(folder, n) for n in os.listdir(folder)) + command[4:],
        capture_output=True, text=True, timeout=120)
    check(command[:3] == ["camhead", "calibrate", "camera"] and
          "6 views of floor board" in fit.stderr and fit.returncode in (0, 3),
          "view: `%s` reads the six (exit %d: %s)"
          % (" ".join(command), fit.returncode, fit.stderr.strip().splitlines()[-1]))
check.finish()
