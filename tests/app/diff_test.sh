#!/usr/bin/env bash
# `tender diff`: cpu and gpu give identical states every tick (exit 0, with `tender sim`'s state
# hash); a one-ULP difference planted after one pass (TENDER_TEST_PLANT_ULP) is found at that tick,
# substep, pass and particle (exit 1); bad input exits 2 with one line.
set -u
. "$(dirname "$0")/lib.sh"

# expect_found OUT PATTERN...: every pattern is in the diff's report
expect_found() {
  local out=$1
  shift
  for pattern in "$@"; do
    grep -qF -- "$pattern" "$out" || fail "'$pattern' not in the report: $(cat "$out")"
  done
}

printf '0 grab particle 383\n1 move 4 -4 6\n40 release\n' >"$tmp/small.txt"
small=(--set cols=16 --set rows=24 --set substeps=4 --set iterations=2)
# The seeds' cloth without contact (contact: the crumple's diff below)
seeds=("${cloth[@]}")

# Identical: the yank (tearing 19 constraints, collision) of a 16 x 24 sheet on cpu and gpu, with
# the state hash of `tender sim`
yank=(--set cols=16 --set rows=24 "${seeds[@]}" --script "$tmp/small.txt" --ticks 60)
"$T" diff "${yank[@]}" --a cpu --b gpu >"$tmp/same" 2>&1
rc=$?
[ "$rc" -eq 0 ] || fail "cpu vs gpu, yank: exit $rc: $(cat "$tmp/same")"
"$T" sim --backend cpu "${yank[@]}" --stats "$tmp/s.json" >/dev/null
hash=$(sed -n 's/.*"state_hash": "\([0-9a-f]*\)".*/\1/p' "$tmp/s.json")
expect_found "$tmp/same" "identical: 60 ticks, state hash $hash"
"$T" diff --preset crumple "${small[@]}" --ticks 30 --a gpu --b gpu-percolor >"$tmp/paths" 2>&1 ||
  fail "fused vs per-colour passes differ: $(cat "$tmp/paths")"

# Planted: one ULP after one pass, found there on both GPU paths and against the CPU itself
plant() { # PLANT A B: diff with the planted change, must exit 1
  TENDER_TEST_PLANT_ULP=$1 "$T" diff --script "$tmp/small.txt" "${small[@]}" "${seeds[@]}" --ticks 12 --a "$2" --b "$3" \
    >"$tmp/found" 2>&1
  local rc=$?
  [ "$rc" -eq 1 ] || fail "planted $1, $2 vs $3: exit $rc: $(cat "$tmp/found")"
  cat "$tmp/found"
}
plant 7:2:project.1.3:200 gpu cpu
expect_found "$tmp/found" "part in tick 7, substep 2, project (iteration 1, colour 3)" "particle 200 pos.x" \
  "1 ULP apart" "identical through tick 6"
plant 4:0:floor:17 cpu gpu-percolor
expect_found "$tmp/found" "part in tick 4, substep 0, floor" "particle 17 pos.x" "1 ULP apart"
plant 9:3:integrate:383 cpu cpu
expect_found "$tmp/found" "part in tick 9, substep 3, integrate" "particle 383 pos.x" "1 ULP apart"
plant 5:1:collide:0 gpu cpu
expect_found "$tmp/found" "part in tick 5, substep 1, collide" "particle 0 pos.x" "1 ULP apart"
plant 0:3:tear:250 cpu gpu
expect_found "$tmp/found" "part in tick 0, substep 3, tear" "particle 250 pos.x" "1 ULP apart"

# Bad input
expect_bad diff --ticks 5 --a cpu
expect_bad diff --ticks 5 --a cpu --b quantum
expect_bad diff --ticks 5 --a cpu:1 --b gpu
expect_bad diff --ticks 5 --a cpu --b gpu:x
expect_bad diff --ticks 5 --a cpu --b gpu:99
expect_bad diff --ticks 0 --a cpu --b cpu
expect_bad diff --ticks 5 --a cpu --b cpu --preset nope
expect_bad diff --ticks 5 --a cpu --b cpu --set damping=2
expect_bad diff --ticks 5 --a cpu --b cpu --script "$tmp/missing.txt"
TENDER_TEST_PLANT_ULP=1:2:bogus:3 expect_bad diff --ticks 5 --a cpu --b cpu
TENDER_TEST_PLANT_ULP=1:0:floor:999999 expect_bad diff --ticks 5 --a cpu --b cpu
TENDER_TEST_PLANT_ULP=1:0:floor:3 expect_bad diff --ticks 5 --a gpu --b gpu-percolor

[ "$failures" -eq 0 ] && echo "ok: tender diff"
exit $((failures > 0))
