#!/usr/bin/env bash
# `tender render` and `tender` without a display: a PNG of the requested size, its path printed,
# exit 0; bad input exits 2 with one line.
set -u
. "$(dirname "$0")/lib.sh"

# Width and height of a PNG from its IHDR chunk.
png_size() { od -An -tu1 -j16 -N8 "$1" | awk '{print $1*16777216+$2*65536+$3*256+$4 "x" $5*16777216+$6*65536+$7*256+$8}'; }

if "$T" render --backend cpu --ticks 5 --width 96 --height 64 --validation --out "$tmp/shot.png" >"$tmp/out" 2>&1; then
  [ "$(png_size "$tmp/shot.png")" = "96x64" ] || fail "render: wrong size $(png_size "$tmp/shot.png")"
  grep -q "shot.png" "$tmp/out" || fail "render: the output path is not printed"
  echo "ok: tender render -> $(cat "$tmp/out")"
else
  fail "tender render exited $?: $(cat "$tmp/out")"
fi

# No display: the main command renders a picture, says where it is, and exits 0.
(cd "$tmp" && env -u DISPLAY -u WAYLAND_DISPLAY "$T" --backend cpu --width 80 --height 64 >"$tmp/out2" 2>&1)
rc=$?
[ "$rc" -eq 0 ] || fail "tender without a display exited $rc: $(cat "$tmp/out2")"
[ -f "$tmp/tender.png" ] && [ "$(png_size "$tmp/tender.png")" = "80x64" ] || fail "tender without a display wrote no 80x64 tender.png"
grep -q "wrote $tmp/tender.png" "$tmp/out2" || fail "tender without a display does not say where the PNG is: $(cat "$tmp/out2")"
[ "$rc" -eq 0 ] && echo "ok: tender (no display) -> $(tail -1 "$tmp/out2")"

# An unreachable display: the same picture, with one line that says why, and exit 0.
rm -f "$tmp/tender.png"
(cd "$tmp" && env -u WAYLAND_DISPLAY DISPLAY=:9999 "$T" --backend cpu --width 80 --height 64 >"$tmp/out3" 2>"$tmp/err3")
rc=$?
[ "$rc" -eq 0 ] || fail "tender with an unreachable display exited $rc: $(cat "$tmp/out3" "$tmp/err3")"
[ -f "$tmp/tender.png" ] && [ "$(png_size "$tmp/tender.png")" = "80x64" ] ||
  fail "tender with an unreachable display wrote no 80x64 tender.png"
head -1 "$tmp/out3" | grep -q "^tender: cannot open a window (.*); rendering a picture instead$" &&
  grep -q "wrote $tmp/tender.png" "$tmp/out3" && [ ! -s "$tmp/err3" ] ||
  fail "tender with an unreachable display should say why in one line, then where the PNG is: $(cat "$tmp/out3" "$tmp/err3")"
[ "$rc" -eq 0 ] && echo "ok: tender (unreachable display) -> $(head -1 "$tmp/out3")"

expect_bad render --width 4 --out "$tmp/x.png"
expect_bad render --backend cpu --ticks 1 --width 64 --height 64 --out /dev/full
printf '0 grab particle 99999\n' >"$tmp/range.txt"
expect_bad render --backend cpu --script "$tmp/range.txt" --out "$tmp/x.png"
# Without a display: --replay and --record are honoured (a missing replay, an unwritable record: exit 2).
expect_bad_nodisplay() {
  (cd "$tmp" && env -u DISPLAY -u WAYLAND_DISPLAY "$T" "$@" >"$tmp/o" 2>"$tmp/e")
  local rc=$?
  if [ "$rc" -ne 2 ] || [ "$(wc -l <"$tmp/e")" -ne 1 ]; then fail "tender $* (no display) -> exit $rc: $(cat "$tmp/e")"; else echo "ok: tender $* (no display) -> $(cat "$tmp/e")"; fi
}
expect_bad_nodisplay --backend cpu --width 64 --height 64 --replay "$tmp/missing.txt"
printf 'garbage\n' >"$tmp/garbage.txt"
expect_bad_nodisplay --backend cpu --width 64 --height 64 --replay "$tmp/garbage.txt"
expect_bad_nodisplay --backend cpu --width 64 --height 64 --record /nonexistent/dir/r.txt
printf '0 wind off\n0 grab particle 1520\n1 move 0 -9 0\n' >"$tmp/replay.txt"
# (the seeds' cloth without contact: with the tender preset's a hand 9 units off drags at 32 substeps a tick)
(cd "$tmp" && env -u DISPLAY -u WAYLAND_DISPLAY "$T" --backend cpu "${cloth[@]}" --width 64 --height 64 --replay replay.txt --record rec.txt >/dev/null 2>&1) &&
  grep -q "move 0 -9 0" "$tmp/rec.txt" && echo "ok: no display: the replay is rendered and recorded" ||
  fail "no display: --replay/--record not honoured"
# --quit-at 1: the picture of step 1, and the recording holds the events before it
(cd "$tmp" && env -u DISPLAY -u WAYLAND_DISPLAY "$T" --backend cpu "${cloth[@]}" --width 64 --height 64 --replay replay.txt --record rec1.txt --quit-at 1 >/dev/null 2>&1) &&
  grep -q "grab particle 1520" "$tmp/rec1.txt" && ! grep -q "move 0 -9 0" "$tmp/rec1.txt" &&
  echo "ok: no display: --quit-at 1 renders and records the session to step 1" ||
  fail "no display: --quit-at not honoured: $(cat "$tmp/rec1.txt")"

# A Vulkan error at run time (the driver cannot allocate under a memory limit) is one line, exit 2.
# 1024 x 1024 without contact: its buffers pass the binding check, its topology fits in the limit
# (out of memory below about 900 MB), and the driver's memory does not (it does above 2 GB).
(ulimit -v 1250000; exec "$T" sim --backend gpu "${cloth[@]}" --set cols=1024 --set rows=1024 --ticks 0) \
  >"$tmp/o" 2>"$tmp/e"
rc=$?
if [ "$rc" -ne 2 ] || [ "$(wc -l <"$tmp/e")" -ne 1 ] || ! grep -q '^tender: error: Vulkan error ' "$tmp/e"; then
  fail "a Vulkan error at run time -> exit $rc: $(cat "$tmp/e")"
else
  echo "ok: a Vulkan error at run time -> $(cat "$tmp/e")"
fi
# A sheet larger than the device binds is refused with one line (512 x 512 with the preset's contact:
# its contact buffer is 163 MiB, where lavapipe binds 128).
expect_bad sim --backend gpu --set cols=512 --set rows=512 --ticks 1
# A script's sheet passes the memory check of --set: 2^24 particles' GPU buffers (about 25 GiB)
# refused before anything is allocated, where this machine's memory cannot hold them.
printf '0 set cols 4096\n0 set rows 4096\n' >"$tmp/grow.txt"
expect_bad sim --backend gpu --script "$tmp/grow.txt" --ticks 1
if [ "$(awk '/^MemAvailable:/ {print $2}' /proc/meminfo)" -lt $((26 * 1024 * 1024)) ]; then
  grep -q "grow.txt: tick 0: set: a 4096x4096 sheet needs about" "$tmp/err" || fail "a script's 4096x4096 sheet: $(cat "$tmp/err")"
fi
# The GPU runs below are the seeds' cloth without contact: a CPU device takes seconds
# to build contact's kernels (contact on the GPU: Parity.*Contact*, the crumple sweeps and diffs).
seeds=("${cloth[@]}")
# Loader notices are not validation messages: the layer enabled through the environment too.
VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation "$T" render --validation --backend gpu "${seeds[@]}" --ticks 3 --width 64 \
  --height 64 --out "$tmp/v.png" >"$tmp/o" 2>"$tmp/e" && echo "ok: VK_INSTANCE_LAYERS with --validation" ||
  fail "VK_INSTANCE_LAYERS with --validation: $(cat "$tmp/e")"
# A sheet of one particle, and a yank to the edge of the allowed coordinates, on the GPU.
"$T" sim --backend gpu --validation "${seeds[@]}" --set cols=1 --set rows=1 --ticks 3 >"$tmp/o" 2>"$tmp/e" && echo "ok: a 1x1 sheet on the GPU" ||
  fail "1x1 sheet on the GPU: $(cat "$tmp/e")"
# (the sheet, which cannot tear, spans the coordinates from the first tick on)
printf '0 grab particle 1535\n1 move 999999 999999 -999999\n' >"$tmp/edge.txt"
"$T" sim --backend gpu "${seeds[@]}" --ticks 20 --set tear_factor=0 --script "$tmp/edge.txt" --stats "$tmp/edge.json" >/dev/null &&
  python3 -c "import json,sys; s=json.load(open(sys.argv[1])); assert s['nan_count']==0, s" "$tmp/edge.json" &&
  echo "ok: a yank to 999999 stays finite on the GPU" || fail "a yank to 999999 on the GPU"
expect_bad render --backend cpu --script "$tmp/missing.txt" --out "$tmp/x.png"
expect_bad render --backend cpu --ticks 1 --out /nonexistent/dir/x.png

[ "$failures" -eq 0 ] && echo PASS || { echo "$failures failures"; exit 1; }
