#!/usr/bin/env bash
# Command-line contract of `tender`: every bad input exits 2 with exactly one line on stderr;
# `tender sim` writes stats JSON and a PLY.
set -u
T=${TENDER:?set TENDER to the tender binary}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0

expect_bad() { # args...: must exit 2 with one stderr line
  "$T" "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$? lines
  lines=$(wc -l <"$tmp/err")
  if [ "$rc" -ne 2 ] || [ "$lines" -ne 1 ]; then
    echo "FAIL: tender $* -> exit $rc, $lines stderr lines:"; cat "$tmp/err"; failures=$((failures + 1))
  else
    echo "ok: tender $* -> $(cat "$tmp/err")"
  fi
}

sim=(sim --backend cpu --ticks 2)
expect_bad "${sim[@]}" --preset nope
expect_bad "${sim[@]}" --set nope=1
expect_bad "${sim[@]}" --set cols=0
expect_bad "${sim[@]}" --set cols=1000000000
expect_bad "${sim[@]}" --set cols=16384 --set rows=16384
expect_bad "${sim[@]}" --set damping=1.5
expect_bad "${sim[@]}" --set damping=abc
expect_bad "${sim[@]}" --set gravity=nan
expect_bad "${sim[@]}" --set pins=middle
expect_bad "${sim[@]}" --set substeps=0
expect_bad "${sim[@]}" --set collision=maybe
expect_bad "${sim[@]}" --set spacing
expect_bad "${sim[@]}" --script "$tmp/missing.txt"
printf '0 grab particle 5\n3 jump\n' >"$tmp/bad.txt"
expect_bad "${sim[@]}" --script "$tmp/bad.txt"
printf '5 release\n2 reset\n' >"$tmp/order.txt"
expect_bad "${sim[@]}" --script "$tmp/order.txt"
expect_bad sim --backend quantum --ticks 2
printf '0 grab particle 99999\n' >"$tmp/range.txt"
expect_bad "${sim[@]}" --script "$tmp/range.txt"
expect_bad "${sim[@]}" --script /
expect_bad sim --ticks -5
expect_bad sim --bogus-flag

# A good run writes stats and a PLY that matches them.
printf '# yank a corner\n0 grab particle 1535\n1 move 4 -4 6\n20 release\n' >"$tmp/yank.txt"
if "$T" sim --backend cpu --ticks 30 --script "$tmp/yank.txt" --stats "$tmp/s.json" --out "$tmp/s.ply" >"$tmp/out"; then
  python3 - "$tmp/s.json" "$tmp/s.ply" <<'PY' || failures=$((failures + 1))
import json, sys
s = json.load(open(sys.argv[1]))
for k in ["particles", "constraints", "colors", "torn", "triangles", "ticks", "ms_per_tick", "state_hash",
          "bbox_min", "bbox_max", "max_stretch", "nan_count"]:
    assert k in s, k
assert s["particles"] == 1536 and s["ticks"] == 30 and s["nan_count"] == 0, s
head = open(sys.argv[2], "rb").read(400).split(b"end_header")[0].decode()
assert "element vertex 1536" in head and f"element face {s['triangles']}" in head, head
print("ok: stats and PLY agree:", s["triangles"], "triangles,", s["torn"], "torn")
PY
else
  echo "FAIL: good sim run exited $?"; failures=$((failures + 1))
fi

"$T" --help >/dev/null && "$T" --version | grep -q '^tender ' || { echo "FAIL: --help/--version"; failures=$((failures + 1)); }
echo "$failures failed"
[ "$failures" -eq 0 ]
