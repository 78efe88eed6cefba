#!/usr/bin/env bash
# What a reload costs the outputs: `camhead run` on the simulated rig,
# reloaded twice mid-run as `systemctl reload` does (SIGHUP under a
# notification socket), first to the demo scene (its bunny's BVH is built
# while frames go on) at more rays, then back. From the record: each
# reload's frame intervals around the switch against the run's median, and
# any frame repeated to fill a gap.
#
#   bench/reload_check.sh CAMHEAD EXECUTOR WIDTHxHEIGHT [OUT_DIR]
#
# EXECUTOR is cpu or gpu. Needs only a shell and awk (no systemd: the
# socket may be absent, camhead's datagrams are then lost as they would be).
set -euo pipefail
cd "$(dirname "$0")/.."
camhead=${1:?CAMHEAD}
executor=${2:?EXECUTOR}
size=${3:?WIDTHxHEIGHT}
out=${4:-$(mktemp -d)}
mkdir -p "$out"
width=${size%x*}
height=${size#*x}
board=$out/reload_board.json
stats=$out/reload_stats.jsonl

write_board() { # SCENE RPP
  cat >"$board.new" <<JSON
{"format": "camhead-board", "version": 1, "name": "reload check",
 "lens": {"profile": "$PWD/scenes/lenses/example_35mm.json",
          "sources": [{"type": "trace", "file": "$PWD/scenes/lenses/sim_focus_pull.csv", "loop": true}]},
 "camera": {"type": "sim", "width": $width, "height": $height, "fps": 25, "samples": 2},
 "scene": "$PWD/scenes/$1", "outputs": ["null"],
 "render": {"executor": "$executor", "rays_per_pixel": $2}}
JSON
  mv "$board.new" "$board"
}

# Waits until the record holds N lines.
wait_lines() {
  for _ in $(seq 600); do
    [ -f "$stats" ] && [ "$(wc -l <"$stats")" -ge "$1" ] && return 0
    sleep 0.1
  done
  echo "reload_check: the record stopped at $(wc -l <"$stats") lines" >&2
  return 1
}

write_board sim_rig.json 4
rm -f "$stats"
NOTIFY_SOCKET=$out/absent.sock "$camhead" run --board "$board" --record-stats "$stats" \
  2>"$out/reload_run.log" &
pid=$!
wait_lines 100
write_board ar_demo.json 9
kill -HUP $pid
wait_lines 250
write_board sim_rig.json 4
kill -HUP $pid
wait_lines 400
kill -TERM $pid
wait $pid
grep -E "reload|frames in" "$out/reload_run.log"

awk -v executor="$executor" -v size="$size" '
  function field(name,   m) {
    if (match($0, "\"" name "\":[-0-9.]+")) return substr($0, RSTART + length(name) + 3, RLENGTH - length(name) - 3)
    return ""
  }
  {
    t[n] = field("output_ns") + 0
    kind[n] = $0 ~ /"kind":"composite"/ ? "c" : "f"
    s = field("setup")
    setup[n] = s == "" ? -1 : s + 0
    n++
  }
  END {
    for (i = 1; i < n; i++) d[i] = (t[i] - t[i - 1]) / 1e6
    m = n - 1
    for (i = 1; i <= m; i++) sorted[i] = d[i]
    # insertion sort: a few hundred intervals
    for (i = 2; i <= m; i++) { v = sorted[i]; j = i - 1; while (j >= 1 && sorted[j] > v) { sorted[j + 1] = sorted[j]; j-- } sorted[j + 1] = v }
    median = sorted[int((m + 1) / 2)]
    fillers = 0
    for (i = 0; i < n; i++) if (kind[i] == "f") fillers++
    printf "%s %s: %d frames out, median interval %.1f ms, %d repeated or placeholder\n", executor, size, n, median, fillers
    last = 0
    for (i = 0; i < n; i++) {
      if (kind[i] != "c") continue
      if (setup[i] != last) {
        worst = 0
        for (j = i - 5; j <= i + 5; j++) if (j >= 1 && j < n && d[j] > worst) worst = d[j]
        printf "  setup %d from output frame %d: longest interval within 5 frames %.1f ms (%.2fx the median)\n", setup[i], i, worst, worst / median
        last = setup[i]
      }
    }
  }' "$stats"
