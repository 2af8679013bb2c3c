#!/usr/bin/env bash
# `tender render --video`: an H.264 MP4 (yuv420p) of seconds x fps frames of the requested size;
# bad input, a missing ffmpeg and failed writes exit 2 with one line and leave no file behind.
set -u
. "$(dirname "$0")/lib.sh"
command -v ffmpeg >/dev/null && command -v ffprobe >/dev/null || { echo "SKIP: ffmpeg or ffprobe missing"; exit 77; }
small=(render --backend cpu --width 160 --height 120)

# A half-second video at 30 fps: 15 frames, 160x120, H.264 in yuv420p, the index (moov) first.
if "$T" "${small[@]}" --seconds 0.5 --fps 30 --video "$tmp/v.mp4" >"$tmp/out" 2>"$tmp/err"; then
  probe=$(ffprobe -v error -select_streams v:0 -count_frames \
    -show_entries stream=codec_name,pix_fmt,width,height,nb_read_frames -of default=nw=1 "$tmp/v.mp4" | sort | tr '\n' ' ')
  want="codec_name=h264 height=120 nb_read_frames=15 pix_fmt=yuv420p width=160 "
  [ "$probe" = "$want" ] && echo "ok: 0.5 s at 30 fps -> $probe" || fail "ffprobe: got '$probe', want '$want'"
  python3 - "$tmp/v.mp4" <<'PY' || fail "the moov atom does not come before mdat (no faststart)"
import sys
d = open(sys.argv[1], "rb").read()
i, boxes = 0, []
while i + 8 <= len(d):
    boxes.append(d[i + 4:i + 8])
    n = int.from_bytes(d[i:i + 4], "big")
    if n < 8: break
    i += n
assert boxes.index(b"moov") < boxes.index(b"mdat"), boxes
PY
  grep -q "15 frames at 30 fps, 60 ticks" "$tmp/out" || fail "summary: $(cat "$tmp/out")"
  [ ! -s "$tmp/err" ] || fail "stderr is not empty when it is not a terminal: $(cat "$tmp/err")"
else
  fail "tender render --video exited $?: $(cat "$tmp/out" "$tmp/err")"
fi

# The simulation keeps its own rate: 120 Hz shown at 25 fps for 61 ticks is 13 frames.
"$T" "${small[@]}" --ticks 61 --fps 25 --video "$tmp/t.mp4" >"$tmp/out" 2>&1 &&
  grep -q "13 frames at 25 fps, 61 ticks" "$tmp/out" &&
  [ "$(ffprobe -v error -count_frames -show_entries stream=nb_read_frames -of csv=p=0 "$tmp/t.mp4")" = 13 ] &&
  echo "ok: --ticks 61 at 25 fps -> 13 frames" || fail "--ticks 61 --fps 25: $(cat "$tmp/out")"

# The GPU backend (its buffers drawn directly): 0.2 s at 30 fps is 6 frames.
"$T" render --backend gpu "${cloth[@]}" --width 96 --height 64 --seconds 0.2 --fps 30 --video "$tmp/g.mp4" >"$tmp/out" 2>&1 &&
  [ "$(ffprobe -v error -count_frames -show_entries stream=nb_read_frames -of csv=p=0 "$tmp/g.mp4")" = 6 ] &&
  echo "ok: the gpu backend -> 6 frames" || fail "--backend gpu: $(cat "$tmp/out")"

for fps in 0 -5 241 nan abc; do expect_bad "${small[@]}" --seconds 0.5 --fps "$fps" --video "$tmp/x.mp4"; done
expect_bad "${small[@]}" --seconds 0.001 --video "$tmp/x.mp4"
expect_bad render --backend cpu --width 161 --height 120 --seconds 0.5 --video "$tmp/x.mp4"
expect_bad "${small[@]}" --seconds 0.5 --video /nonexistent/dir/x.mp4
expect_bad "${small[@]}" --seconds 0.5 --video "$tmp"
expect_bad "${small[@]}" --seconds 0.5 --video /dev/full
# No ffmpeg on PATH: one line that says so.
env PATH=/nonexistent "$T" "${small[@]}" --seconds 0.5 --video "$tmp/x.mp4" >"$tmp/o" 2>"$tmp/e"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$tmp/e")" -eq 1 ] && grep -q "ffmpeg" "$tmp/e" && echo "ok: no ffmpeg -> $(cat "$tmp/e")" ||
  fail "no ffmpeg -> exit $rc: $(cat "$tmp/e")"
[ -e "$tmp/x.mp4" ] && fail "a failed run left x.mp4"

# A write that fails part-way (the file-size limit) exits 2 and keeps the earlier video whole.
cp "$tmp/v.mp4" "$tmp/keep.mp4"
(ulimit -f 2; exec "$T" render --backend cpu --width 320 --height 240 --seconds 1 --video "$tmp/keep.mp4") >"$tmp/o" 2>"$tmp/e"
rc=$?
if [ "$rc" -ne 2 ] || [ "$(wc -l <"$tmp/e")" -ne 1 ] || ! cmp -s "$tmp/keep.mp4" "$tmp/v.mp4"; then
  fail "over the file-size limit -> exit $rc: $(cat "$tmp/e")"
else
  echo "ok: over the file-size limit -> $(cat "$tmp/e"), earlier video intact"
fi
ls -A "$tmp" | grep -q '\.tmp\.' && fail "a temporary file was left: $(ls -A "$tmp")"

# Interrupted (Ctrl-C): ffmpeg stopped, no file, no temporary file.
"$T" render --backend cpu --width 320 --height 240 --seconds 60 --video "$tmp/int.mp4" >/dev/null 2>"$tmp/e" &
victim=$!
sleep 1.5
kill -INT "$victim"
wait "$victim"
rc=$?
if [ "$rc" -eq 0 ] || [ -e "$tmp/int.mp4" ] || ls -A "$tmp" | grep -q '\.tmp\.'; then
  fail "an interrupted video -> exit $rc, left: $(ls -A "$tmp")"
else
  echo "ok: an interrupted video -> exit $rc $(cat "$tmp/e"), nothing left"
fi

[ "$failures" -eq 0 ] && echo PASS || { echo "$failures failures"; exit 1; }
