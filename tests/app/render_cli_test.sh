#!/usr/bin/env bash
# `tender render` and `tender` without a display: a PNG of the requested size, its path printed,
# exit 0; bad input exits 2 with one line.
set -u
T=${TENDER:?set TENDER to the tender binary}
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

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

expect_bad() {
  "$T" "$@" >"$tmp/o" 2>"$tmp/e"
  local rc=$?
  if [ "$rc" -ne 2 ] || [ "$(wc -l <"$tmp/e")" -ne 1 ]; then fail "tender $* -> exit $rc: $(cat "$tmp/e")"; else echo "ok: tender $* -> $(cat "$tmp/e")"; fi
}
expect_bad render --width 4 --out "$tmp/x.png"
expect_bad render --backend cpu --script "$tmp/missing.txt" --out "$tmp/x.png"
expect_bad render --backend cpu --ticks 1 --out /nonexistent/dir/x.png

[ "$failures" -eq 0 ] && echo PASS || { echo "$failures failures"; exit 1; }
