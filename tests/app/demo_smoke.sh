#!/usr/bin/env bash
# Windowed smoke test of tender-demo under Xvfb: drag the sheet, orbit, zoom, pan, resize,
# minimise and restore, press every key; the program must stay up and answer, the grab must catch
# the sheet and move it, and the validation layers must stay silent. On lavapipe without --backend
# it simulates on the CPU. Exits 77 (skipped) without Xvfb or xdotool.
set -u
source "$(dirname "$0")/demo_lib.sh"

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
start_demo --backend cpu --validation --record "$tmp/input.txt" --width 800 --height 600
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
# Every key: reset, wind, FPS, pins, pause and resume, follow on and off.
for key in r w i p space space i f f; do
  xdotool key --window "$wid" "$key"
  sleep 0.3
  alive "key $key"
done
xdotool getwindowname "$wid" >/dev/null || fail "the window does not answer"
shot after
stop_demo
cat "$tmp/demo.log"
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

# SIGTERM (as Ctrl-C) ends the session as a window close does: the recording and the summary are
# written, then one error line and exit 2; the recording replays to the demo's state.
start_demo --backend cpu --record "$tmp/term.txt" --width 640 --height 480
sleep 3
alive "start-up before SIGTERM"
xdotool mousemove --sync 320 240 mousedown 1 mousemove --sync 300 260 mouseup 1
sleep 0.5
kill -TERM "$demo"
wait "$demo"
rc=$?
demo=
[ "$rc" -eq 2 ] || fail "SIGTERM: exit $rc"
grep -q "^tender: error: interrupted (SIGTERM); the session is recorded in $tmp/term.txt$" "$tmp/demo.log" ||
  fail "SIGTERM: no error line naming the recording"
steps=$(sed -n 's/^tender-demo: \([0-9]*\) steps, state hash \([0-9a-f]*\)$/\1/p' "$tmp/demo.log")
hash=$(sed -n 's/^tender-demo: \([0-9]*\) steps, state hash \([0-9a-f]*\)$/\2/p' "$tmp/demo.log")
[ -n "$steps" ] && [ -n "$hash" ] || fail "SIGTERM: no summary"
grep -q "steps: tender sim --script <this file> --ticks $steps ends at state hash $hash" "$tmp/term.txt" ||
  fail "SIGTERM: the recording was not written"
"$(dirname "$DEMO")/tender" sim --backend cpu --script "$tmp/term.txt" --ticks "$steps" | grep -q "state hash $hash" ||
  fail "SIGTERM: the recording does not replay to the demo's state"
echo "ok: SIGTERM ends the session with its recording ($steps steps) and summary"

# The launcher `tender` passes SIGINT, SIGTERM and SIGHUP sent to its pid alone (a supervisor's,
# `timeout`'s) on to the demo it started: the demo ends its session with its recording, and its
# status is the launcher's; nothing is left running.
launcher_bin=$(dirname "$DEMO")/tender
for sig in INT TERM HUP; do
  display_up
  "$launcher_bin" --backend cpu --record "$tmp/launched_$sig.txt" --width 640 --height 480 >"$tmp/demo.log" 2>&1 &
  launcher=$!
  demo=
  for _ in $(seq 100); do
    demo=$(pgrep -P "$launcher" -x tender-demo)
    [ -n "$demo" ] && xdotool search --name "Tender" >/dev/null 2>&1 && break
    sleep 0.1
  done
  [ -n "$demo" ] || { kill -KILL "$launcher"; fail "SIG$sig: tender started no tender-demo with a window"; }
  sleep 1
  kill -"$sig" "$launcher"
  for _ in $(seq 100); do kill -0 "$launcher" 2>/dev/null || break; sleep 0.1; done
  if kill -0 "$launcher" 2>/dev/null; then
    kill -KILL "$demo" "$launcher"
    fail "SIG$sig to tender's pid: still running 10 s later"
  fi
  wait "$launcher"
  rc=$?
  kill -0 "$demo" 2>/dev/null && { kill -KILL "$demo"; fail "SIG$sig to tender's pid: tender-demo was left running"; }
  demo=
  [ "$rc" -eq 2 ] || fail "SIG$sig to tender's pid: exit $rc"
  grep -q "^tender: error: interrupted (SIG$sig); the session is recorded in $tmp/launched_$sig.txt$" "$tmp/demo.log" ||
    fail "SIG$sig to tender's pid: no error line naming the recording"
  grep -q "steps: tender sim --script <this file>" "$tmp/launched_$sig.txt" ||
    fail "SIG$sig to tender's pid: the recording was not written"
done
echo "ok: SIGINT, SIGTERM and SIGHUP sent to tender's pid alone end the demo's session with its recording"

# On a CPU device (lavapipe here) the demo simulates on the CPU backend unless --backend says
# otherwise, and draws a cheaper picture; its output, the HUD and --help say so.
"$DEMO" --help | grep -q 'cpu when its Vulkan device is a CPU device' || fail "--help does not say how --backend is chosen"
start_demo --width 320 --height 240
sleep 2
alive "start-up without --backend"
stop_demo
grep -q 'is a CPU device: simulating on the CPU, no MSAA, 1024² shadows$' "$tmp/demo.log" ||
  fail "without --backend on a CPU device, not the CPU backend"
echo "ok: $(grep 'is a CPU device' "$tmp/demo.log")"
echo "PASS"
