#!/usr/bin/env bash
# Preset files: `tender presets` lists the presets, `--dump NAME` prints one as JSON (every key),
# and `--preset-file` of that JSON runs bitwise the same as `--preset NAME`; a bad file exits 2
# with one line that names it.
set -u
. "$(dirname "$0")/lib.sh"
hash_of() { "$T" sim --backend cpu "$@" | grep -o 'state hash [0-9a-f]*'; }

[ "$("$T" presets | tr '\n' ' ')" = "tender crumple tender-low crumple-low paper " ] && echo "ok: tender presets" ||
  fail "tender presets: $("$T" presets 2>&1)"

# Every key is dumped, and the dump round-trips to the same state.
for p in crumple tender-low; do
  "$T" presets --dump "$p" >"$tmp/$p.json" || fail "presets --dump $p exited $?"
  python3 - "$tmp/$p.json" "$p" "$T" <<'PY' || fail "presets --dump $p: not every key"
import json, subprocess, sys
d = json.load(open(sys.argv[1]))
help_text = subprocess.run([sys.argv[3], "--help"], capture_output=True, text=True).stdout
keys = [l.split()[0] for l in help_text.split("Parameter keys for --set:")[1].splitlines() if l.strip()]
assert d["preset"] == sys.argv[2], d
assert set(d) == set(keys) | {"preset"}, set(d) ^ (set(keys) | {"preset"})
PY
  a=$(hash_of --preset-file "$tmp/$p.json" --ticks 20) b=$(hash_of --preset "$p" --ticks 20)
  [ -n "$a" ] && [ "$a" = "$b" ] && echo "ok: --preset-file of the $p dump: $a" || fail "$p round trip: '$a' vs '$b'"
done

# A partial file starts from its "preset" (or tender), and --set applies on top.
printf '{"preset": "crumple", "cols": 12, "rows": 14, "collision": false, "pins": "none", "gravity": "2.5"}\n' >"$tmp/part.json"
a=$(hash_of --preset-file "$tmp/part.json" --set rows=10 --ticks 20)
b=$(hash_of --preset crumple --set cols=12 --set rows=10 --set collision=off --set pins=none --set gravity=2.5 --ticks 20)
[ -n "$a" ] && [ "$a" = "$b" ] && echo "ok: a partial preset file and --set on top" || fail "partial file: '$a' vs '$b'"
printf '{"cols": 12}\n' >"$tmp/nobase.json"
a=$(hash_of --preset-file "$tmp/nobase.json" --ticks 5) b=$(hash_of --set cols=12 --ticks 5)
[ -n "$a" ] && [ "$a" = "$b" ] && echo "ok: without \"preset\" a file starts from tender" || fail "no base: '$a' vs '$b'"

expect_bad() { # file content, then args: exit 2, one line naming the file
  local name=$1 content=$2
  shift 2
  [ "$content" = - ] || printf '%s' "$content" >"$tmp/$name"
  "$T" "$@" --preset-file "$tmp/$name" >"$tmp/o" 2>"$tmp/e"
  local rc=$?
  if [ "$rc" -ne 2 ] || [ "$(wc -l <"$tmp/e")" -ne 1 ] || ! grep -q "^tender: error: $tmp/$name: " "$tmp/e"; then
    fail "$name ($content) -> exit $rc: $(cat "$tmp/e")"
  else
    echo "ok: $name -> $(cat "$tmp/e")"
  fi
}
sim=(sim --backend cpu --ticks 2)
expect_bad unknown.json '{"cols": 10, "nope": 1}' "${sim[@]}"
expect_bad value.json '{"cols": "abc"}' "${sim[@]}"
expect_bad range.json '{"damping": 1.5}' "${sim[@]}"
expect_bad fraction.json '{"cols": 10.5}' "${sim[@]}"
expect_bad enum.json '{"pins": "middle"}' "${sim[@]}"
expect_bad null.json '{"cols": null}' "${sim[@]}"
expect_bad truncated.json '{"cols": 10,' "${sim[@]}"
expect_bad trailing.json $'{"cols": 10}\n{"rows": 3}' "${sim[@]}"
expect_bad array.json '[1, 2]' "${sim[@]}"
expect_bad preset.json '{"preset": "nope"}' "${sim[@]}"
expect_bad empty.json '' "${sim[@]}"
expect_bad missing.json - "${sim[@]}"
expect_bad unknown.json - render --backend cpu --out "$tmp/x.png"
expect_bad unknown.json - diff --ticks 1 --a cpu --b cpu
"$T" "${sim[@]}" --preset crumple --preset-file "$tmp/part.json" >/dev/null 2>"$tmp/e"
[ $? -eq 2 ] && [ "$(wc -l <"$tmp/e")" -eq 1 ] && echo "ok: --preset with --preset-file -> $(cat "$tmp/e")" ||
  fail "--preset with --preset-file: $(cat "$tmp/e")"
"$T" presets --dump nope >/dev/null 2>"$tmp/e"
[ $? -eq 2 ] && [ "$(wc -l <"$tmp/e")" -eq 1 ] && echo "ok: presets --dump nope -> $(cat "$tmp/e")" ||
  fail "presets --dump nope: $(cat "$tmp/e")"

[ "$failures" -eq 0 ] && echo PASS || { echo "$failures failures"; exit 1; }
