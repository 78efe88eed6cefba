#!/bin/sh
# Outputs a hostile but fair user gives camhead (issue 12): a FIFO or a
# device node where a file goes, a folder, a file-size limit, a profile that
# fails after the output was named. Each must be refused or leave what was
# there as it was. Usage: hostile_outputs.sh CAMHEAD SOURCE_DIR
. "$(dirname "$0")/expect.sh"

measurements=$src/scenes/lenses/example_35mm_measurements.csv
scene=$src/bench/scenes/small_ball.json

# A FIFO (what a device node is to a rename) is refused, and stays a FIFO.
mkfifo "$tmp/fifo"
expect 4 "not a regular file" "$camhead" calibrate "$measurements" --prime --name x -o "$tmp/fifo"
[ -p "$tmp/fifo" ] || fail "calibrate replaced the FIFO"
expect 5 "not a regular file" "$camhead" lens record --duration 0.2 -o "$tmp/fifo"
[ -p "$tmp/fifo" ] || fail "lens record replaced the FIFO"
mkfifo "$tmp/fifo.png"
expect 4 "not a regular file" "$camhead" render "$scene" --cpu --rpp 1 -o "$tmp/fifo.png"
[ -p "$tmp/fifo.png" ] || fail "render replaced the FIFO"

# A folder where the image goes: refused before the render.
mkdir "$tmp/folder.png"
expect 4 "a folder" "$camhead" render "$scene" --cpu --rpp 1 -o "$tmp/folder.png"

# A symbolic link stands for its target, which is replaced; the link stays.
echo old >"$tmp/target.json"
ln -s target.json "$tmp/link.json"
expect 0 "written" "$camhead" calibrate "$measurements" --prime --name x -o "$tmp/link.json"
[ -L "$tmp/link.json" ] || fail "calibrate replaced the symbolic link"
grep -q '"camhead-lens-profile"' "$tmp/target.json" || fail "the link's target was not written"

# A render whose write fails half-way (a file-size limit) leaves the
# previous image as it was, and no partial file.
"$camhead" render "$scene" --cpu --rpp 1 -o "$tmp/frame.exr" >/dev/null 2>&1 ||
  fail "the first render failed"
cp "$tmp/frame.exr" "$tmp/frame.before"
(
  trap '' XFSZ
  ulimit -f 64
  "$camhead" render "$scene" --cpu --rpp 1 -o "$tmp/frame.exr" >"$tmp/out" 2>&1
  [ $? -eq 4 ] || echo "exit $?" >"$tmp/limited"
)
[ -e "$tmp/limited" ] && fail "render under a size limit: $(cat "$tmp/limited") $(cat "$tmp/out")"
cmp -s "$tmp/frame.exr" "$tmp/frame.before" || fail "a failed render changed the previous image"
[ -e "$tmp/frame.exr.partial" ] && fail "a failed render left frame.exr.partial"

# lens record with a profile that fails to load: the trace a user had stays.
sed "s|\.\./scenes/lenses/example_35mm.json|$tmp/bad_profile.json|; s|\.\./scenes/lenses/sim_focus_pull.csv|$src/scenes/lenses/sim_focus_pull.csv|" \
  "$src/board/sim.json" >"$tmp/board.json"
echo '{"format": "camhead-lens-profile", "version": 1}' >"$tmp/bad_profile.json"
echo "the user's trace" >"$tmp/take.csv"
"$camhead" lens record --board "$tmp/board.json" --duration 0.2 -o "$tmp/take.csv" >"$tmp/out" 2>&1 &&
  fail "lens record with a broken profile succeeded: $(cat "$tmp/out")"
[ "$(cat "$tmp/take.csv")" = "the user's trace" ] || fail "lens record replaced the user's trace"

# More threads than the machine can start: an error, not an abort (where
# the address space is limited; sanitizer builds need all of it).
if ! ldd "$camhead" 2>/dev/null | grep -q libasan; then
  (
    ulimit -v 600000
    "$camhead" render "$scene" --cpu --rpp 1 --threads 1000 -o "$tmp/threads.png" >"$tmp/out" 2>&1
    echo $? >"$tmp/status"
  )
  status=$(cat "$tmp/status")
  [ "$status" -eq 0 ] || grep -q "cannot start thread" "$tmp/out" ||
    fail "render --threads 1000 under a memory limit exited $status: $(cat "$tmp/out")"
fi

[ "$failures" -eq 0 ] && echo "hostile outputs: all refused or left intact"
exit "$failures"
