#!/bin/sh
# `camhead run` as a hostile but fair user drives it (issue 23): a take that
# breaks off, a pose with no view, an output or statistics file over the
# run's own input, a NUL in a path, a size the take cannot deliver, a
# file-size limit, command-line values that mean nothing. Each must end in a
# named error with its documented exit status (docs/input-errors.md), and
# leave every file that was there as it was.
# Usage: hostile_run.sh CAMHEAD SOURCE_DIR
. "$(dirname "$0")/expect.sh"

# y4m FILE FRAMES [BAD]: a 64x48 4:2:2 take of FRAMES mid-grey frames (6144
# bytes each); frame number BAD, if given, behind a garbled FRAME line.
y4m() {
  {
    printf 'YUV4MPEG2 W64 H48 F25:1 Ip A1:1 C422 XCOLORRANGE=LIMITED\n'
    i=0
    while [ "$i" -lt "$2" ]; do
      if [ "$i" -eq "${3:--1}" ]; then printf 'FRAXE\n'; else printf 'FRAME\n'; fi
      head -c 6144 /dev/zero | tr '\000' '\200'
      i=$((i + 1))
    done
  } >"$1"
}

# board FILE CAMERA [MORE]: the sim rig's lens and scene, CAMERA as its camera.
board() {
  cat >"$1" <<EOF
{"format": "camhead-board", "version": 1, "name": "hostile",
 "lens": {"profile": "$src/scenes/lenses/example_35mm.json",
          "sources": [{"type": "trace", "file": "$src/scenes/lenses/sim_focus_pull.csv"}]},
 "camera": $2, "scene": "$src/scenes/sim_rig.json", "outputs": ["null"]${3:-}}
EOF
}
offline='"type": "file", "width": 64, "height": 48, "loop": false, "realtime": false'

cd "$tmp" || exit 1

# A take that breaks off is named by file and frame, exits 5, and what was
# composited before the break is kept, whole.
y4m take.y4m 10
head -c $(($(wc -c <take.y4m) - 100)) take.y4m >cut.y4m
board cut.json "{$offline, \"path\": \"$tmp/cut.y4m\"}"
expect 5 "the camera failed: .*cut.y4m:frame 9: truncated: 6044 of 6144 bytes" \
  "$camhead" run --board cut.json --output file:cut_out.y4m
[ "$(grep -c FRAME cut_out.y4m)" -eq 9 ] || fail "the cut take's 9 whole frames were not kept"
y4m garbled.y4m 10 1
board garbled.json "{$offline, \"path\": \"$tmp/garbled.y4m\"}"
expect 5 "garbled.y4m:frame 1: garbled: 'FRAXE' where FRAME should be" \
  "$camhead" run --board garbled.json --output null

# A pose the renderer cannot build a view from is refused (it rendered the
# plate alone, silently), and so is a rig looking straight down without "up".
board pose.json '{"type": "sim", "width": 64, "height": 48}' \
  ', "pose": {"position": [0, 3, -2], "look_at": [0, 0, -2]}'
expect 2 "pose.up: missing, and the default \[0, 1, 0\] is parallel" \
  "$camhead" run --board pose.json --frames 1

# An output or the statistics file that is the camera's own take is refused
# before anything is opened for writing; the take stays as it was.
cp take.y4m take.before
board take.json "{$offline, \"path\": \"$tmp/take.y4m\"}"
expect 2 "file:take.y4m: writes to take.y4m, which is the camera's take that this run reads" \
  "$camhead" run --board take.json --output file:take.y4m
expect 2 "--record-stats: writes to take.y4m, which is the camera's take" \
  "$camhead" run --board take.json --output null --record-stats take.y4m
ln -s take.y4m alias.y4m
expect 2 "which is the camera's take" "$camhead" run --board take.json --output file:alias.y4m
cmp -s take.y4m take.before || fail "a refused run changed the camera's take"
expect 2 "writes to board.json, which is the board" \
  sh -c "cp take.json board.json && \"$camhead\" run --board board.json --output null --record-stats board.json"

# The other commands that write what a board or the user reads: a lens
# recording over the trace the board replays, a profile over its own
# measurements.
cp "$src/scenes/lenses/sim_focus_pull.csv" pull.csv
cp "$src/scenes/lenses/example_35mm_measurements.csv" measurements.csv
sed "s|$src/scenes/lenses/sim_focus_pull.csv|$tmp/pull.csv|" take.json >pull.json
expect 2 "-o pull.csv: writes to pull.csv, which is lens source \"trace\"'s trace" \
  "$camhead" lens record --board pull.json --duration 0.2 -o pull.csv
cmp -s pull.csv "$src/scenes/lenses/sim_focus_pull.csv" || fail "lens record changed its trace"
expect 2 "which is the measurements" \
  "$camhead" calibrate measurements.csv --prime --name x -o measurements.csv
cmp -s measurements.csv "$src/scenes/lenses/example_35mm_measurements.csv" ||
  fail "calibrate changed its measurements"

# A NUL in a path would open another file than the one named (./victim).
board nul.json '{"type": "sim", "width": 64, "height": 48}' \
  ', "pose": {"position": [0, 1, 0], "look_at": [0, 1, -2]}'
sed 's|"outputs": \["null"\]|"outputs": ["file:victim\\u0000.y4m"]|' nul.json >nul_output.json
expect 2 "holds a NUL character" "$camhead" run --board nul_output.json --frames 1
[ -e victim ] && fail "a NUL in an output path wrote ./victim"
board nul_take.json "{$offline, \"path\": \"$tmp/take.y4m\\u0000.png\"}"
expect 2 "camera.path: holds a NUL character" "$camhead" run --board nul_take.json --frames 1

# Sizes: past the image limit, refused from the board; a take that cannot
# deliver the board's size, refused before a frame buffer of it is made.
board huge.json '{"type": "sim", "width": 8192, "height": 8192}'
expect 2 "camera.width: 8192x8192 is more than 2^25 pixels" "$camhead" run --board huge.json
printf 'YUV4MPEG2 W7680 H4320 F25:1 C422\nFRAME\n' >tiny.y4m
head -c 1500 /dev/zero >>tiny.y4m
board tiny.json '{"type": "file", "path": "'"$tmp"'/tiny.y4m", "width": 7680, "height": 4320}'
if ! ldd "$camhead" 2>/dev/null | grep -q libasan; then
  # The renderer at 7680x4320 needs gigabytes: under a 2 GB limit, only a
  # check made before it allocates can answer.
  (
    failures=0
    ulimit -v 2000000
    expect 2 "tiny.y4m:frame 0: truncated: 1500 of 66355200 bytes" \
      "$camhead" run --board tiny.json --executor cpu
    [ "$failures" -eq 0 ] || echo fail >tiny.failed
  )
  [ -e tiny.failed ] && failures=$((failures + 1))
fi

# A file-size limit: the recording is cut back to its last whole frame and
# kept, the summary counts what was written, and the exit is 4.
(
  ulimit -f 30 # 30 blocks of 512 bytes: the header and 2 frames
  "$camhead" run --board take.json --output file:limited.y4m >out 2>&1
  echo $? >status
)
[ "$(cat status)" -eq 4 ] || fail "a run under ulimit -f exited $(cat status): $(cat out)"
grep -q "File too large" out || fail "a run under ulimit -f did not say why: $(cat out)"
grep -q "file limited.y4m: frames written 2, lost 8" out ||
  fail "a run under ulimit -f did not count what it wrote: $(cat out)"
[ "$(grep -c FRAME limited.y4m)" -eq 2 ] || fail "limited.y4m does not hold its 2 whole frames"
[ -e limited.y4m.partial ] && fail "a run under ulimit -f left limited.y4m.partial"

# A full disk, the same: a 32 KiB tmpfs in a mount namespace of its own,
# where root may make one (skipped elsewhere). The header (57 bytes) and 5
# frames of 6150 make 30807 bytes; a sixth frame does not fit.
mkdir small
if unshare --mount sh -c "mount -t tmpfs -o size=32k tmpfs small" 2>/dev/null; then
  unshare --mount sh -c "mount -t tmpfs -o size=32k tmpfs small &&
    \"$camhead\" run --board take.json --output file:small/full.y4m >out 2>&1
    echo \$? >status; grep -c FRAME small/full.y4m >frames; ls small >left"
  [ "$(cat status)" -eq 4 ] || fail "a run on a full disk exited $(cat status): $(cat out)"
  grep -q "No space left on device" out || fail "a run on a full disk did not say why: $(cat out)"
  grep -q "file small/full.y4m: frames written 5, lost 5" out ||
    fail "a run on a full disk did not count what it wrote: $(cat out)"
  [ "$(cat frames)" -eq 5 ] || fail "full.y4m does not hold its 5 whole frames"
  [ "$(cat left)" = full.y4m ] || fail "a run on a full disk left $(cat left)"
else
  echo "hostile run: no full-disk check (no mount namespace here)"
fi

# Command-line values that mean nothing are input errors (2), not "no
# limit" or CLI11's own exit codes.
for value in nan 0 -1 inf; do
  expect 2 "is not a number of seconds above 0" "$camhead" run --duration "$value" --output null
done
expect 2 "is not a number of frames above 0" "$camhead" run --frames 0 --output null
expect 2 "" "$camhead" run --no-such-flag
expect 2 "pattern:" "$camhead" run --frames 1 --output "file:frames/%q%d.png"

# A board field that would be ignored, or given twice, is refused.
board format.json "{$offline, \"path\": \"$tmp/take.y4m\", \"format\": \"nv12\"}"
expect 2 "camera.format: a file camera's frames are in the file's own format" \
  "$camhead" run --board format.json
sed 's|"camera": |"camera": {"type": "sim"}, "camera": |' take.json >twice.json
expect 2 "camera: given twice in one object" "$camhead" run --board twice.json

[ "$failures" -eq 0 ] && echo "hostile run: every input refused or named, every file intact"
exit "$failures"
