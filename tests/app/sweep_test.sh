#!/usr/bin/env bash
# `tender sweep` and `tender sweep-merge`: a grid's lines in the documented order; each sheet ends
# where `tender sim` alone ends (tearing or not); odd batches and shards give the same lines (all
# but the "batch" timings); samples are reproducible; bad input exits 2 with one line.
set -u
. "$(dirname "$0")/lib.sh"

PY=${PYTHON:-python3}
# The seeds' cloth without contact (a sweep with contact: the crumple's below)
small=(--backend cpu "${cloth[@]}" --set cols=8 --set rows=12)
# Grab the bottom right corner (particle 95 of 8x12) and yank it hard: tear_factor decides.
printf '0 grab particle 95\n1 move 4 -4 6\n40 release\n' >"$tmp/yank.txt"

# lines DIR: its sheets.jsonl without the "batch" field of each line (timings), one per line
lines() { "$PY" -c 'import json,sys
for l in open(sys.argv[1]):
    j = json.loads(l); j.pop("batch"); print(json.dumps(j))' "$1/sheets.jsonl"; }
# sweep ARGS...: tender sweep, which must succeed
sweep() { "$T" sweep "$@" >"$tmp/sweep.out" 2>&1 || fail "tender sweep $*: $(cat "$tmp/sweep.out")"; }

# 1. A grid of two keys: 6 sheets, the last --vary changing fastest
sweep "${small[@]}" --vary damping=0.98,0.99 --vary gravity=9:10:3 --ticks 10 --out "$tmp/grid"
grep -q '^tender sweep: 6 of 6 sheets (shard 0/1) of 8x12, 10 ticks on cpu' "$tmp/sweep.out" ||
  fail "summary: $(cat "$tmp/sweep.out")"
"$PY" - "$tmp/grid/sheets.jsonl" <<'EOF' || fail "grid order"
import json, sys
got = [json.loads(l) for l in open(sys.argv[1])]
want = [{"damping": d, "gravity": g} for d in (0.98, 0.99) for g in (9.0, 9.5, 10.0)]
assert [j["index"] for j in got] == list(range(6)), [j["index"] for j in got]
assert [j["values"] for j in got] == want, [j["values"] for j in got]
assert all(len(j["state_hash"]) == 16 and j["ticks"] == 10 and "ms_per_tick" in j["batch"] for j in got)
assert len({j["state_hash"] for j in got}) == 6
EOF

# 2. Every sheet ends where `tender sim` alone ends, torn or not
sweep "${small[@]}" --script "$tmp/yank.txt" --vary tear_factor=0,1.5,50 --vary damping=0.98,0.99 --ticks 60 \
  --out "$tmp/tear" --ply
"$PY" - "$tmp/tear/sheets.jsonl" >"$tmp/alone.txt" <<'EOF' || fail "tear sweep"
import json, sys
got = [json.loads(l) for l in open(sys.argv[1])]
torn = [j["torn"] for j in got]
assert min(torn) == 0 and max(torn) > 0, torn  # some sheets tear, others do not
for j in got:
    sets = " ".join("--set %s=%r" % kv for kv in j["values"].items())
    print(j["index"], j["state_hash"], j["torn"], sets)
EOF
while read -r index hash torn sets; do
  # shellcheck disable=SC2086
  "$T" sim "${small[@]}" $sets --script "$tmp/yank.txt" --ticks 60 --stats "$tmp/alone.json" \
    --out "$tmp/alone.ply" >/dev/null || fail "tender sim $sets"
  alone=$("$PY" -c 'import json,sys; j=json.load(open(sys.argv[1])); print(j["state_hash"], j["torn"])' \
    "$tmp/alone.json")
  [ "$alone" = "$hash $torn" ] || fail "sheet $index ($sets): sweep $hash $torn, alone $alone"
  cmp -s "$tmp/alone.ply" "$tmp/tear/$(printf 'sheet_%06d.ply' "$index")" || fail "sheet $index: PLY differs"
done <"$tmp/alone.txt"
[ "$(wc -l <"$tmp/alone.txt")" -eq 6 ] || fail "tear sweep: $(wc -l <"$tmp/alone.txt") sheets"

# 3. 37 sheets in batches of 8 (the last one of 5) give the lines of one batch
odd=("${small[@]}" --script "$tmp/yank.txt" --vary tear_factor=1:3:37 --ticks 45)
sweep "${odd[@]}" --batch 8 --out "$tmp/b8"
sweep "${odd[@]}" --out "$tmp/whole"
[ "$(wc -l <"$tmp/whole/sheets.jsonl")" -eq 37 ] || fail "37 sheets: $(wc -l <"$tmp/whole/sheets.jsonl") lines"
cmp -s <(lines "$tmp/b8") <(lines "$tmp/whole") || fail "--batch 8 and one batch differ"
grep -q '"batch":{"sheets":5,' "$tmp/b8/sheets.jsonl" || fail "no last batch of 5 sheets"

# 4. Three shards merged are the whole sweep; missing, doubled and foreign shards are refused
for i in 0 1 2; do sweep "${odd[@]}" --shard "$i/3" --out "$tmp/shard$i"; done
[ "$(wc -l <"$tmp/shard1/sheets.jsonl")" -eq 12 ] || fail "shard 1/3 of 37: not 12 sheets"
"$T" sweep-merge "$tmp/shard2" "$tmp/shard0" "$tmp/shard1" --out "$tmp/merged" >"$tmp/merge.out" 2>&1 ||
  fail "sweep-merge: $(cat "$tmp/merge.out")"
cmp -s <(lines "$tmp/merged") <(lines "$tmp/whole") || fail "merged shards differ from the whole sweep"
cmp -s "$tmp/merged/sweep.json" "$tmp/whole/sweep.json" || fail "merged sweep.json differs from the whole sweep's"
expect_bad sweep-merge "$tmp/shard0" "$tmp/shard1" --out "$tmp/m2"
grep -q 'missing: 2, 5, 8' "$tmp/err" || fail "missing sheets not named: $(cat "$tmp/err")"
expect_bad sweep-merge "$tmp/shard0" "$tmp/shard1" "$tmp/shard2" "$tmp/shard1" --out "$tmp/m3"
grep -q 'sheet 1 is doubled' "$tmp/err" || fail "doubled sheet not named: $(cat "$tmp/err")"
sweep "${small[@]}" --script "$tmp/yank.txt" --vary tear_factor=1:3:37 --ticks 44 --shard 2/3 --out "$tmp/other"
expect_bad sweep-merge "$tmp/shard0" "$tmp/shard1" "$tmp/other" --out "$tmp/m4"
grep -q 'another sweep.*ticks differs' "$tmp/err" || fail "foreign shard: $(cat "$tmp/err")"
expect_bad sweep-merge --out "$tmp/m5"
expect_bad sweep-merge "$tmp/missing" --out "$tmp/m6"
mkdir -p "$tmp/broken" && cp "$tmp/shard0/sweep.json" "$tmp/broken/" && echo '{"index": "x"}' >"$tmp/broken/sheets.jsonl"
expect_bad sweep-merge "$tmp/broken" --out "$tmp/m7"
[ ! -e "$tmp/m2/sheets.jsonl" ] || fail "a refused merge wrote its output"

# 5. Samples: the same seed draws the same values, another seed others, all within the ranges
samples=("${small[@]}" --vary damping=0.9:1 --vary substeps=2:6 --vary wind_kind=sinusoid,noise --samples 12 --ticks 3)
sweep "${samples[@]}" --seed 7 --out "$tmp/s7"
sweep "${samples[@]}" --seed 7 --out "$tmp/s7b"
sweep "${samples[@]}" --seed 8 --out "$tmp/s8"
"$PY" - "$tmp/s7" "$tmp/s7b" "$tmp/s8" <<'EOF' || fail "samples"
import json, sys
a, b, c = ([json.loads(l)["values"] for l in open(d + "/sheets.jsonl")] for d in sys.argv[1:])
assert a == b and a != c, (a, c)
for v in a + c:
    assert 0.9 <= v["damping"] <= 1 and v["substeps"] in range(2, 7) and v["wind_kind"] in ("sinusoid", "noise"), v
assert len({v["damping"] for v in a}) == 12 and len({v["substeps"] for v in a + c}) > 2
EOF

# A small GPU sweep ends where the CPU's does (bitwise), where this build has Vulkan
if "$T" devices >/dev/null 2>&1; then
  sweep --backend gpu "${cloth[@]}" --set cols=8 --set rows=12 --script "$tmp/yank.txt" --vary tear_factor=0,1.5,50 \
    --vary damping=0.98,0.99 --ticks 60 --batch 4 --out "$tmp/gpu"
  cmp -s <(lines "$tmp/gpu" | sed 's/"arithmetic": {[^}]*}, "backend": "[a-z]*", //') \
    <(lines "$tmp/tear" | sed 's/"arithmetic": {[^}]*}, "backend": "[a-z]*", //') ||
    fail "gpu and cpu sweeps differ"
  # With the crumple preset's contact: the same stats, its count of particles in contact included
  # (15 ticks: the yanked sheet at damping 0.98 still has particles in contact then)
  paper=(--preset crumple --set cols=8 --set rows=12 --script "$tmp/yank.txt" --vary damping=0.98,0.99 --ticks 15)
  sweep --backend gpu "${paper[@]}" --batch 2 --out "$tmp/gpu_contact"
  sweep --backend cpu "${paper[@]}" --out "$tmp/cpu_contact"
  grep -q '"contacts":[1-9]' "$tmp/cpu_contact/sheets.jsonl" || fail "no contact in the crumple sweep"
  cmp -s <(lines "$tmp/gpu_contact" | sed 's/"arithmetic": {[^}]*}, "backend": "[a-z]*", //') \
    <(lines "$tmp/cpu_contact" | sed 's/"arithmetic": {[^}]*}, "backend": "[a-z]*", //') ||
    fail "gpu and cpu sweeps with contact differ"
  # Sheets too large for the fused tick run the per-colour passes batched, with the same results
  big=("${cloth[@]}" --set cols=64 --set rows=96 --vary damping=0.98,0.99 --ticks 4)
  sweep --backend gpu "${big[@]}" --out "$tmp/gpu_big"
  sweep --backend cpu "${big[@]}" --out "$tmp/cpu_big"
  "$PY" - "$tmp/gpu_big" "$tmp/cpu_big" <<'EOF' || fail "large sheets on gpu: $(cat "$tmp/gpu_big/sheets.jsonl")"
import json, sys
g, c = ([json.loads(l) for l in open(d + "/sheets.jsonl")] for d in sys.argv[1:])
assert [j["state_hash"] for j in g] == [j["state_hash"] for j in c] and all(j["batch"]["sheets"] == 2 for j in g)
EOF
fi

# 6. Bad input
expect_bad sweep "${small[@]}" --vary nope=1,2 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary cols=8,9 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary tri_bend=on,off --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.5,2 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping= --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.5,,0.6 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.5:0.6:0 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.5:0.6 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.5:x:3 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary wind=on:off:2 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary substeps=1.5,2 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --vary damping=0.8 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9:1:3 --samples 4 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9:1 --samples 0 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --seed 3 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary collision_factor=1,3 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --shard 0/0 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --shard 3/3 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --shard 1 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --shard -1/3 --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --batch 0 --ticks 5 --out "$tmp/bad"
expect_bad sweep --backend cpu --set cols=256 --set rows=256 --vary damping=0:1:2000 --batch 2000 --ticks 5 \
  --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --ticks 0 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --ticks 5
expect_bad sweep "${small[@]}" --ticks 5 --out "$tmp/bad"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --ticks 5 --out /proc/tender-sweep
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --ticks 5 --out "$tmp/yank.txt"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --ticks 5 --script "$tmp/missing.txt" --out "$tmp/bad"
printf '0 grab particle 96\n' >"$tmp/far.txt"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --ticks 5 --script "$tmp/far.txt" --out "$tmp/bad"
# Contact turned on by the script in sheets made without it: refused before any tick, on every backend
printf '0 grab particle 27\n2 set contact_factor 0.5\n' >"$tmp/contact_later.txt"
expect_bad sweep "${small[@]}" --vary damping=0.9,1 --ticks 5 --script "$tmp/contact_later.txt" --out "$tmp/bad"
grep -q 'set contact_factor' "$tmp/err" || fail "contact turned on later: $(cat "$tmp/err")"
[ ! -e "$tmp/bad" ] || fail "bad input created its --out folder"

[ "$failures" -eq 0 ] && echo "ok: tender sweep"
exit $((failures > 0))
