#!/usr/bin/env bash
# The GPU proof kit: tools/gpu-bundle packs this build's programs into a folder, a copy of the
# folder elsewhere (the original removed) runs `gpu-check --smoke` (every check once, on the least
# that runs it; the full and quick runs are for real GPUs) in an environment holding only
# PATH, HOME and the driver (lavapipe and its cache), exits 0 and writes a report naming every check; bad usage
# exits 2 with one line. Also the kit's shape: at most 60 MiB, stripped programs with an RPATH
# into the kit, a validation layer manifest that points into the kit.
set -u
BUILD=${TENDER_BUILD_DIR:?set TENDER_BUILD_DIR to the build folder}
SRC=$(cd "$(dirname "$0")/../.." && pwd -P)
DRIVER=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

"$SRC/tools/gpu-bundle" --build-dir "$BUILD" "$tmp/made/kit" >"$tmp/bundle.out" 2>&1
rc=$?
if [ "$rc" -ne 0 ]; then
  fail "gpu-bundle exited $rc: $(cat "$tmp/bundle.out")"
  exit 1
fi
echo "ok: $(head -1 "$tmp/bundle.out")"
kit=$tmp/elsewhere/kit
mkdir -p "$tmp/elsewhere" && cp -r "$tmp/made/kit" "$kit" && rm -rf "$tmp/made"

# The kit's shape.
size=$(du -sb "$kit" | cut -f1)
[ "$size" -le $((60 * 1024 * 1024)) ] || fail "the kit is $size bytes, over 60 MiB"
for f in gpu-check tender tender-bench bin/tender bin/tender-bench bin/tender_gpu_tests bin/tender_render_tests \
  lib/libvulkan.so.1 lib/libVkLayer_khronos_validation.so lib/libfreetype.so.6 lib/compat/libstdc++.so.6 \
  share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json MANIFEST.txt env.sh; do
  [ -e "$kit/$f" ] || fail "the kit has no $f"
done
for f in "$kit"/bin/tender*; do
  readelf -S "$f" | grep -q '\.symtab' && fail "$(basename "$f") is not stripped"
  if command -v patchelf >/dev/null; then
    readelf -d "$f" | grep -Eq '(RUNPATH|RPATH).*\$ORIGIN/\.\./lib' || fail "$(basename "$f") has no RPATH into the kit"
  fi
done
grep -q '"library_path": "../../../lib/libVkLayer_khronos_validation.so"' \
  "$kit/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json" || fail "the layer manifest's library_path"
# The driver's settings pass: its shader cache (Mesa's and the validation layer's, under
# XDG_CACHE_HOME; cold, the kit's dozen programs compile every pipeline again) and LP_NUM_THREADS.
scrubbed=(env -i PATH=/usr/bin:/bin HOME="$tmp" VK_DRIVER_FILES="$DRIVER" XDG_CACHE_HOME="${XDG_CACHE_HOME:-$HOME/.cache}"
  ${LP_NUM_THREADS:+LP_NUM_THREADS="$LP_NUM_THREADS"})
"${scrubbed[@]}" "$kit/tender" --version | grep -q '^tender ' || fail "the kit's tender --version"

# gpu-check --smoke from the copy, in a scrubbed environment.
start=$(date +%s)
# Two shards: the tests' logs are gathered from two processes (one on a 2-core machine otherwise).
"${scrubbed[@]}" "$kit/gpu-check" --smoke --shards 2 --out "$tmp/report" >"$tmp/check.out" 2>&1
rc=$?
echo "gpu-check --smoke: exit $rc in $(($(date +%s) - start)) s"
report=$tmp/report/report.md
if [ "$rc" -ne 0 ]; then
  fail "gpu-check --smoke exited $rc"
  cat "$tmp/check.out"
  for log in "$tmp"/report/logs/*.log; do
    echo "--- $(basename "$log") (last lines)"
    tail -5 "$log"
  done
fi
if [ -f "$report" ]; then
  for check in environment devices gpu-tests render-tests diff-tender-hanging diff-tender-yank diff-crumple-hanging \
    diff-crumple-yank diff-crumple-contact contact realtime bench fleet fleet-large; do
    grep -q "^| $check | .* | pass | " "$report" || fail "report.md: check $check did not pass or is missing"
  done
  grep -q '^\*\*PASS\*\*: .* (smoke mode)' "$report" || fail "report.md does not say PASS in smoke mode"
  # The shards' counts add up to the whole binary's.
  render_count=$("${scrubbed[@]}" "$kit/bin/tender_render_tests" --gtest_list_tests \
    --gtest_filter='Camera.*:Receipt.*:Golden.TornSheetShowsTheGap' | grep -c '^  ')
  grep -q "^| render-tests | .* | $render_count tests, $render_count passed (2 processes) |" "$report" ||
    fail "report.md: render-tests did not count $render_count tests from 2 processes"
  # The real-time table: the smoke mode's one gesture, 2 ticks, against the crumple preset's period
  grep -q '^| crumple | toss | 2 | [0-9.]* | [0-9.]* | 16.7 | [0-9.]* | [0-9.]* | 0 |$' "$report" ||
    fail "report.md has no real-time row for the crumple's toss"
  grep -q '^| dispatch cost | [0-9.]* us per empty dispatch' "$report" || fail "report.md has no dispatch cost"
  grep -q '^| 64x64 | 4096 | gpu-percolor | [0-9]' "$report" || fail "report.md has no benchmark table"
  [ -s "$tmp/report/bench.json" ] && [ -s "$tmp/report/bench.csv" ] || fail "no bench.json or bench.csv"
  grep -q '^32x48 *gpu *4 *[0-9.]' "$report" || fail "report.md has no fleet table with a batch of 4"
  grep -q '^64x64 *gpu *4 *[0-9.]' "$report" || fail "report.md has no large-sheet fleet table with a batch of 4"
  [ -s "$tmp/report/fleet.json" ] && [ -s "$tmp/report/fleet-large.json" ] || fail "no fleet.json or fleet-large.json"
  if command -v gnuplot >/dev/null && command -v python3 >/dev/null; then
    [ -s "$tmp/report/fleet.png" ] || fail "no fleet.png (gnuplot and python3 are here)"
  fi
  for f in "$tmp"/report/*.tmp "$tmp"/report/.*.tmp "$tmp"/report/logs/*.tmp; do
    [ -e "$f" ] && fail "a temporary file is left: $f"
  done
  echo "ok: report.md:"
  sed -n '/^## Checks/,/^Logs/p' "$report"
else
  fail "gpu-check wrote no report.md"
fi

# Bad usage: exit 2, one line.
expect_usage() {
  "${scrubbed[@]}" "$kit/gpu-check" "$@" >"$tmp/o" 2>"$tmp/e"
  local rc=$?
  if [ "$rc" -ne 2 ] || [ "$(wc -l <"$tmp/e")" -ne 1 ] || ! grep -q '^gpu-check: error: ' "$tmp/e"; then
    fail "gpu-check $* -> exit $rc: $(cat "$tmp/e")"
  else
    echo "ok: gpu-check $* -> $(cat "$tmp/e")"
  fi
}
expect_usage
expect_usage --quick
expect_usage --out
expect_usage --bogus --out "$tmp/x"
expect_usage --out /proc/version/x
expect_usage --shards 0 --out "$tmp/x"
expect_usage --shards many --out "$tmp/x"
"$SRC/tools/gpu-bundle" >/dev/null 2>"$tmp/e"
[ $? -eq 2 ] || fail "gpu-bundle without OUT_DIR should exit 2"
"$SRC/tools/gpu-bundle" --build-dir "$tmp/nope" "$tmp/k2" >/dev/null 2>"$tmp/e"
[ $? -eq 2 ] && grep -q '^gpu-bundle: error: ' "$tmp/e" || fail "gpu-bundle --build-dir of a missing folder: $(cat "$tmp/e")"

echo "$failures failed"
[ "$failures" -eq 0 ]
