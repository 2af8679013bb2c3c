#!/usr/bin/env bash
# `tender sim --backend gpu` on an emulated inexact device (TENDER_EMULATE_INEXACT_MATH=1: sqrt and
# divide off by up to 3 ULP) gives the CPU reference's state hash and says so in its stats; with
# the correction switched off (TENDER_UNCORRECTED_MATH=1) the hash differs.
set -u
. "$(dirname "$0")/lib.sh"
hash_of() { sed -n 's/.*"state_hash": "\([0-9a-f]*\)".*/\1/p' "$1"; }

printf '0 grab particle 383\n1 move 4 -4 6\n40 release\n' >"$tmp/yank.txt"
# The seeds' cloth at 16 x 24 (contact's arithmetic on the inexact device:
# gpu.parity_on_inexact_device), to just past the release: the yank has torn all it tears (19
# constraints, by tick 5)
run=(sim --ticks 45 "${cloth[@]}" --set cols=16 --set rows=24 --script "$tmp/yank.txt")
"$T" "${run[@]}" --backend cpu --stats "$tmp/cpu.json" >/dev/null || fail "cpu run failed"
TENDER_EMULATE_INEXACT_MATH=1 "$T" "${run[@]}" --backend gpu --stats "$tmp/gpu.json" >/dev/null || fail "gpu run failed"
TENDER_EMULATE_INEXACT_MATH=1 TENDER_UNCORRECTED_MATH=1 "$T" "${run[@]}" --backend gpu --stats "$tmp/raw.json" >/dev/null ||
  fail "uncorrected gpu run failed"
cpu=$(hash_of "$tmp/cpu.json") gpu=$(hash_of "$tmp/gpu.json") raw=$(hash_of "$tmp/raw.json")
[ -n "$cpu" ] && [ "$cpu" = "$gpu" ] || fail "inexact device: gpu hash '$gpu' != cpu hash '$cpu'"
[ -n "$raw" ] && [ "$raw" != "$cpu" ] || fail "without the correction the hash should differ from the cpu's ($raw)"
grep -q '"inexact_math_emulated": true' "$tmp/gpu.json" || fail "the stats do not say the emulation was on"
grep -q '"inexact_math_emulated": false' "$tmp/cpu.json" || fail "the cpu stats should say inexact_math_emulated false"
[ "$failures" -eq 0 ] && echo "ok: inexact device gives the cpu's hash $cpu; uncorrected gives $raw"
exit $((failures > 0))
