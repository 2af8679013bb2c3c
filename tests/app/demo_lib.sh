# Shared by the windowed demo tests (sourced): starts Xvfb on a free display and removes it and
# `tmp` at exit (exits 77, skipped, without the X tools); `fail MESSAGE` prints the demo's output
# and exits 1; `start_demo ARGS...` runs tender-demo with ARGS (output in $tmp/demo.log) and sets
# `demo` and `wid` once its window is up; `stop_demo` presses Escape and checks a clean exit (a demo stuck for 60 s fails the test).
DEMO=${TENDER_DEMO:?set TENDER_DEMO to the tender-demo binary}
for tool in Xvfb xdotool xwd convert xdpyinfo; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIP: $tool is not installed (apt-get install xvfb xdotool x11-apps x11-utils imagemagick)"
    exit 77
  fi
done
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}
tmp=$(mktemp -d)
# Xvfb picks a free display itself (-displayfd writes its number). -noreset: by default Xvfb resets
# when its last client leaves, and a demo that connects during the reset (the next start_demo after
# a stop_demo) finds no display.
Xvfb -displayfd 3 -screen 0 1024x768x24 -nolisten tcp -noreset 3>"$tmp/display" >"$tmp/xvfb.log" 2>&1 &
xvfb=$!
demo=
cleanup() {
  [ -n "$demo" ] && kill "$demo" 2>/dev/null
  kill "$xvfb" 2>/dev/null
  wait 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
for _ in $(seq 100); do [ -s "$tmp/display" ] && break; sleep 0.1; done
display=":$(head -1 "$tmp/display")"
export DISPLAY=$display
# Waits until the display answers (10 s at most); fails when Xvfb has gone.
display_up() {
  local _
  for _ in $(seq 100); do xdpyinfo >/dev/null 2>&1 && return 0; sleep 0.1; done
  kill -0 "$xvfb" 2>/dev/null || fail "Xvfb on $display has exited"
  fail "Xvfb on $display does not answer"
}

fail() { echo "FAIL: $*"; echo "--- demo output"; cat "$tmp/demo.log" 2>/dev/null; echo "--- Xvfb"; cat "$tmp/xvfb.log"; exit 1; }
alive() { kill -0 "$demo" 2>/dev/null || fail "tender-demo exited during: $1"; }
shot() { xwd -root -silent | convert xwd:- "$tmp/$1.png"; }

start_demo() {
  display_up
  "$DEMO" "$@" >"$tmp/demo.log" 2>&1 &
  demo=$!
  wid=
  for _ in $(seq 100); do
    wid=$(xdotool search --name "Tender" 2>/dev/null | head -1)
    [ -n "$wid" ] && break
    sleep 0.1
  done
  [ -n "$wid" ] || fail "no window appeared"
}

# Each thread of process $1: its name, its kernel wait channel and the CPU time it took over one
# second (in clock ticks: a thread busy all the second takes about 100), so that a demo that does
# not exit tells a thread waiting for ever from one still working; with gdb, the stacks too.
stuck_threads() {
  local t before=() i=0
  for t in /proc/"$1"/task/*; do before+=("$(awk '{print $14 + $15}' "$t/stat" 2>/dev/null)"); done
  sleep 1
  for t in /proc/"$1"/task/*; do
    echo "$(cat "$t/comm" 2>/dev/null): $(cat "$t/wchan" 2>/dev/null), $(($(awk '{print $14 + $15}' "$t/stat" 2>/dev/null || echo 0) - ${before[i]:-0})) ticks in 1 s"
    i=$((i + 1))
  done
  if command -v gdb >/dev/null; then
    timeout 30 gdb -batch -p "$1" -ex "thread apply all bt 12" 2>/dev/null | grep '^#\|^Thread'
  fi
}

stop_demo() {
  # Escape again each second, in case one is lost; a demo still running after 60 s is stuck: the
  # threads' kernel wait channels say where, and it is stopped (TERM, then KILL) so that the test
  # fails rather than hangs. (60 s: with Mesa's shader cache cold, as on a fresh machine, lavapipe
  # was seen taking over 20 s to finish the frame in flight at 2 FPS, one llvmpipe thread busy.)
  local i
  for i in $(seq 600); do
    kill -0 "$demo" 2>/dev/null || break
    [ $((i % 10)) -eq 1 ] && xdotool key --window "$wid" Escape 2>/dev/null
    sleep 0.1
  done
  if kill -0 "$demo" 2>/dev/null; then
    local where
    where=$(stuck_threads "$demo")
    # SIGTERM ends a demo whose frame loop still runs (the summary lines then reach its output)
    local term="SIGTERM ended it"
    kill -TERM "$demo" 2>/dev/null
    for i in $(seq 50); do kill -0 "$demo" 2>/dev/null || break; sleep 0.1; done
    if kill -0 "$demo" 2>/dev/null; then
      term="SIGTERM did not end it either: killed"
      kill -KILL "$demo" 2>/dev/null
    fi
    wait "$demo"
    demo=
    fail "tender-demo did not exit within 60 s of Escape ($term); its threads (name: wait channel, CPU time):
$where"
  fi
  wait "$demo"
  local rc=$?
  demo=
  [ "$rc" -eq 0 ] || fail "tender-demo exited with status $rc"
}
