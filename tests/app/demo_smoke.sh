#!/usr/bin/env bash
# Windowed smoke test of tender-demo under Xvfb: drag the sheet, orbit, zoom, pan, resize,
# minimise and restore, press every key; the program must stay up and answer, the grab must catch
# the sheet and move it, and the validation layers must stay silent. Exits 77 (skipped) without
# Xvfb or xdotool.
set -u
DEMO=${TENDER_DEMO:?set TENDER_DEMO to the tender-demo binary}
for tool in Xvfb xdotool xwd convert; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIP: $tool is not installed (apt-get install xvfb xdotool x11-apps imagemagick)"
    exit 77
  fi
done
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}
tmp=$(mktemp -d)
display=":$((90 + RANDOM % 400))"
Xvfb "$display" -screen 0 1024x768x24 -nolisten tcp >"$tmp/xvfb.log" 2>&1 &
xvfb=$!
demo=
cleanup() {
  [ -n "$demo" ] && kill "$demo" 2>/dev/null
  kill "$xvfb" 2>/dev/null
  wait 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
export DISPLAY=$display
for _ in $(seq 50); do xdpyinfo >/dev/null 2>&1 && break; sleep 0.1; done

fail() { echo "FAIL: $*"; echo "--- demo output"; cat "$tmp/demo.log"; exit 1; }

# No usable display: one line `tender: error: ...` naming the cause, exit 2.
DISPLAY=:9999 "$DEMO" --backend cpu >"$tmp/nodisplay.out" 2>"$tmp/nodisplay.err"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$tmp/nodisplay.err")" -eq 1 ] && grep -q '^tender: error: ' "$tmp/nodisplay.err" ||
  { cat "$tmp/nodisplay.err"; fail "no usable display -> exit $rc, not one error line"; }
echo "ok: no usable display -> $(cat "$tmp/nodisplay.err")"
# An unwritable --record is refused before the window opens.
"$DEMO" --backend cpu --record /nonexistent/dir/input.txt >/dev/null 2>"$tmp/record.err"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$tmp/record.err")" -eq 1 ] || { cat "$tmp/record.err"; fail "unwritable --record -> exit $rc"; }
alive() { kill -0 "$demo" 2>/dev/null || fail "tender-demo exited during: $1"; }
shot() { xwd -root -silent | convert xwd:- "$tmp/$1.png"; }

"$DEMO" --backend cpu --validation --record "$tmp/input.txt" --width 800 --height 600 >"$tmp/demo.log" 2>&1 &
demo=$!
wid=
for _ in $(seq 100); do
  wid=$(xdotool search --name "Tender" 2>/dev/null | head -1)
  [ -n "$wid" ] && break
  sleep 0.1
done
[ -n "$wid" ] || fail "no window appeared"
echo "window $wid: $(xdotool getwindowname "$wid")"
sleep 3 # pipelines build, the sheet settles
alive "start-up"
xdotool key --window "$wid" w # wind off: only the grab moves the sheet from here on
sleep 1
shot before

# Left-drag the middle of the sheet down and to the left.
xdotool mousemove --sync 400 300 mousedown 1
for i in $(seq 1 12); do xdotool mousemove --sync $((400 - 12 * i)) $((300 + 10 * i)); sleep 0.05; done
sleep 0.5
shot dragged
xdotool mouseup 1
alive "drag"
# Right-drag orbits, the wheel zooms, middle-drag pans.
xdotool mousemove --sync 600 200 mousedown 3 mousemove --sync 650 220 mousemove --sync 700 240 mouseup 3
xdotool click 4 click 4 click 5
xdotool mousemove --sync 500 500 mousedown 2 mousemove --sync 520 490 mouseup 2
alive "orbit, zoom, pan"
# Resize, minimise, restore.
xdotool windowsize --sync "$wid" 640 480 || true
sleep 0.5
alive "resize"
xdotool windowminimize "$wid" 2>/dev/null || true
xdotool windowunmap --sync "$wid"
sleep 0.5
alive "minimise"
xdotool windowmap --sync "$wid"
xdotool windowsize --sync "$wid" 900 650 || true
sleep 0.5
alive "restore"
# Every key: reset, wind, FPS, pins, pause and resume.
for key in r w i p space space i; do
  xdotool key --window "$wid" "$key"
  sleep 0.3
  alive "key $key"
done
xdotool getwindowname "$wid" >/dev/null || fail "the window does not answer"
shot after
xdotool key --window "$wid" Escape
for _ in $(seq 100); do kill -0 "$demo" 2>/dev/null || break; sleep 0.1; done
wait "$demo"
rc=$?
demo=
cat "$tmp/demo.log"
[ "$rc" -eq 0 ] || fail "tender-demo exited with status $rc"
grep -q "validation" "$tmp/demo.log" && fail "validation messages"
grep -Eq "[1-9][0-9]* grabs" "$tmp/demo.log" || fail "the drag did not grab the sheet"
for ev in "grab ray" "move" "release" "reset" "wind" "pins" "pause"; do
  grep -q "$ev" "$tmp/input.txt" || fail "the recorded input has no '$ev' event"
done
# The recording is the session: `tender sim` of it ends in the demo's state, step for step.
steps=$(sed -n 's/^tender-demo: \([0-9]*\) steps, state hash \([0-9a-f]*\)$/\1/p' "$tmp/demo.log")
hash=$(sed -n 's/^tender-demo: \([0-9]*\) steps, state hash \([0-9a-f]*\)$/\2/p' "$tmp/demo.log")
[ -n "$steps" ] && [ -n "$hash" ] || fail "the demo printed no step count and state hash"
"$(dirname "$DEMO")/tender" sim --backend cpu --script "$tmp/input.txt" --ticks "$steps" >"$tmp/sim.log" 2>&1 ||
  fail "tender sim of the recording failed: $(cat "$tmp/sim.log")"
grep -q "state hash $hash" "$tmp/sim.log" || fail "tender sim of the recording does not end at the demo's state hash $hash: $(cat "$tmp/sim.log")"
grep -q "steps: tender sim --script <this file> --ticks $steps ends at state hash $hash" "$tmp/input.txt" ||
  fail "the recording does not say how many steps it holds"
# The sheet moved: the screen while dragging differs from the screen before.
changed=$(compare -metric AE -fuzz 3% "$tmp/before.png" "$tmp/dragged.png" null: 2>&1 | cut -d' ' -f1)
echo "pixels changed by the drag: $changed"
[ "${changed%.*}" -gt 2000 ] || fail "the sheet did not move ($changed pixels changed)"
echo "recorded input:"; head -20 "$tmp/input.txt"
echo "PASS"
