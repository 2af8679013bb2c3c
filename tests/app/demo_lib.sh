# Shared by the windowed demo tests (sourced): starts Xvfb on a free display and removes it and
# `tmp` at exit (exits 77, skipped, without the X tools); `fail MESSAGE` prints the demo's output
# and exits 1; `start_demo ARGS...` runs tender-demo with ARGS (output in $tmp/demo.log) and sets
# `demo` and `wid` once its window is up; `stop_demo` presses Escape and checks a clean exit.
DEMO=${TENDER_DEMO:?set TENDER_DEMO to the tender-demo binary}
for tool in Xvfb xdotool xwd convert xdpyinfo; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIP: $tool is not installed (apt-get install xvfb xdotool x11-apps x11-utils imagemagick)"
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
for _ in $(seq 100); do xdpyinfo >/dev/null 2>&1 && break; sleep 0.1; done

fail() { echo "FAIL: $*"; echo "--- demo output"; cat "$tmp/demo.log" 2>/dev/null; echo "--- Xvfb"; cat "$tmp/xvfb.log"; exit 1; }
alive() { kill -0 "$demo" 2>/dev/null || fail "tender-demo exited during: $1"; }
shot() { xwd -root -silent | convert xwd:- "$tmp/$1.png"; }

start_demo() {
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

stop_demo() {
  xdotool key --window "$wid" Escape
  for _ in $(seq 100); do kill -0 "$demo" 2>/dev/null || break; sleep 0.1; done
  wait "$demo"
  local rc=$?
  demo=
  [ "$rc" -eq 0 ] || fail "tender-demo exited with status $rc"
}
