#!/usr/bin/env python3
"""`camhead run` as systemd runs it, reloaded as `systemctl reload` does.

A notification socket of our own stands in for systemd (NOTIFY_SOCKET):
camhead must say READY=1 once its first frame is out; on SIGHUP,
RELOADING=1 with the time, then READY=1 and a STATUS= that says what
happened: a board with a new render setting is taken (the record's frames
after it carry "setup": 1 and the new rays per pixel), a broken one is
refused with its file named, the status lines after it keep saying so,
and the run goes on; SIGTERM ends it with exit
status 0 and a summary that counts both.

    service_reload.py CAMHEAD SOURCE_DIR SCRATCH_DIR
"""
import json
import os
import signal
import socket
import subprocess
import sys
import time

camhead, source, scratch = sys.argv[1:4]
os.makedirs(scratch, exist_ok=True)
board = os.path.join(scratch, "board.json")
stats = os.path.join(scratch, "stats.jsonl")
sock_path = os.path.join(scratch, "notify.sock")


def write_board(rays_per_pixel):
    lenses = os.path.join(source, "scenes", "lenses")
    text = json.dumps({
        "format": "camhead-board", "version": 1, "name": "reload",
        "lens": {"profile": os.path.join(lenses, "example_35mm.json"),
                 "sources": [{"type": "trace", "file": os.path.join(lenses, "sim_focus_pull.csv")}]},
        "camera": {"type": "sim", "width": 64, "height": 32, "fps": 25},
        "scene": os.path.join(source, "scenes", "sim_rig.json"),
        "outputs": ["null"],
        "render": {"executor": "cpu", "rays_per_pixel": rays_per_pixel}})
    with open(board + ".new", "w") as f:
        f.write(text)
    os.replace(board + ".new", board)  # as an editor saves: never half a file


def fail(message):
    print("FAIL " + message)
    sys.exit(1)


write_board(2)
if os.path.exists(sock_path):
    os.unlink(sock_path)
listener = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
listener.bind(sock_path)
listener.settimeout(120)

env = dict(os.environ, NOTIFY_SOCKET=sock_path)
run = subprocess.Popen([camhead, "run", "--board", board, "--record-stats", stats],
                       env=env, stderr=subprocess.PIPE, text=True)


def expect(prefix):
    """The next message that is not a status line or a watchdog ping."""
    while True:
        try:
            message = listener.recv(4096).decode()
        except socket.timeout:
            run.kill()
            fail("no %r from camhead within 120 s; stderr:\n%s" % (prefix, run.communicate()[1]))
        if message.startswith("STATUS=") or message == "WATCHDOG=1":
            continue
        if not message.startswith(prefix):
            run.kill()
            fail("expected %r, got %r" % (prefix, message))
        return message


def composites():
    try:
        with open(stats) as f:
            return [json.loads(line) for line in f if '"kind":"composite"' in line]
    except FileNotFoundError:
        return []


def wait_for(predicate, what):
    deadline = time.monotonic() + 60
    while not predicate():
        if time.monotonic() > deadline:
            run.kill()
            fail("no %s within 60 s" % what)
        time.sleep(0.05)


expect("READY=1")
# READY=1 comes with the first frame out, which on a slow start is the
# placeholder: the first setup's composites come before the reload.
wait_for(lambda: len(composites()) >= 3, "composites of the first setup")
write_board(3)
run.send_signal(signal.SIGHUP)
reloading = expect("RELOADING=1\n")
if "MONOTONIC_USEC=" not in reloading:
    fail("RELOADING=1 without MONOTONIC_USEC: %r" % reloading)
taken = expect("READY=1\nSTATUS=")
if "reloaded " + board not in taken:
    fail("the reload was not taken: %r" % taken)

with open(board, "w") as f:
    f.write('{"format": "camhead-board", ')  # broken: the run must go on
run.send_signal(signal.SIGHUP)
expect("RELOADING=1\n")
refused = expect("READY=1\nSTATUS=")
if "reload refused" not in refused or board not in refused:
    fail("a broken board was not refused naming it: %r" % refused)
# The status line that follows keeps the refusal: `systemctl status` shows
# why the board on disk is not the one running.
while True:
    try:
        message = listener.recv(4096).decode()
    except socket.timeout:
        fail("no status line after the refusal")
    if message.startswith("STATUS=in "):
        break
if "reload refused" not in message:
    fail("the status line dropped the refusal: %r" % message)

# Frames go on after the refusal, with the setup that was taken.
wait_for(lambda: sum(1 for c in composites() if c["setup"] == 1) >= 10,
         "frames of the reloaded setup")
run.send_signal(signal.SIGTERM)
_, stderr = run.communicate(timeout=60)
sys.stderr.write(stderr)
if run.returncode != 0:
    fail("exit status %d" % run.returncode)
if "reloads 1, refused 1" not in stderr:
    fail("the summary does not count the reloads")
records = composites()
setups = [c["setup"] for c in records]
if setups != sorted(setups) or set(setups) != {0, 1}:
    fail("setups not 0 then 1: %r" % setups)
for c in records:
    if c["rpp"] != (2 if c["setup"] == 0 else 3):
        fail("frame %d of setup %d has %d rays per pixel" % (c["sequence"], c["setup"], c["rpp"]))
print("PASS %d frames of setup 0, %d of setup 1" % (setups.count(0), setups.count(1)))
