#!/usr/bin/env bash
# Command-line contract of `tender`: every bad input exits 2 with exactly one line on stderr;
# `tender sim` writes stats JSON and a PLY.
set -u
. "$(dirname "$0")/lib.sh"

sim=(sim --backend cpu --ticks 2)
expect_bad "${sim[@]}" --preset nope
expect_bad "${sim[@]}" --set nope=1
expect_bad "${sim[@]}" --set cols=0
expect_bad "${sim[@]}" --set cols=1000000000
expect_bad "${sim[@]}" --set cols=16384 --set rows=16384
expect_bad "${sim[@]}" --set damping=1.5
expect_bad "${sim[@]}" --set damping=abc
expect_bad "${sim[@]}" --set gravity=nan
# The stretch limit is a ratio to rest: 0 (off) or at least 1
expect_bad "${sim[@]}" --set stretch_limit=0.5
expect_bad "${sim[@]}" --set stretch_limit=-1
expect_bad "${sim[@]}" --set stretch_limit=inf
# Contact's radius: 0 (off) or 0.25 to 0.75 spacings (a denormal is neither)
expect_bad "${sim[@]}" --set contact_factor=1e-38
expect_bad "${sim[@]}" --set contact_factor=2
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
expect_bad "${sim[@]}" --ticks 0x10
expect_bad "${sim[@]}" --ticks 100000001
# Coordinates beyond +-1e6 (or beyond float) are refused; a tick number must fit.
printf '0 grab particle 1535\n1 move 1e30 1e30 1e30\n' >"$tmp/far.txt"
expect_bad "${sim[@]}" --script "$tmp/far.txt"
printf '0 grab particle 1535\n1 move 1e39 0 0\n' >"$tmp/inf.txt"
expect_bad "${sim[@]}" --script "$tmp/inf.txt"
printf '0 grab ray 3e38 0 10 0 0 -1\n' >"$tmp/ray.txt"
expect_bad "${sim[@]}" --script "$tmp/ray.txt"
printf '99999999999999999999999 reset\n' >"$tmp/tick.txt"
expect_bad "${sim[@]}" --script "$tmp/tick.txt"
# Outputs: checked before the run, never two outputs in one file, write errors are errors.
expect_bad "${sim[@]}" --stats /dev/full
expect_bad "${sim[@]}" --out /dev/full
expect_bad "${sim[@]}" --stats "$tmp/same" --out "$tmp/same"
expect_bad "${sim[@]}" --stats "$tmp/nostats.json" --out /nonexistent/dir/x.ply
[ -e "$tmp/nostats.json" ] && { echo "FAIL: a failed run left its stats file"; failures=$((failures + 1)); }
expect_bad "${sim[@]}" --stats "$tmp"

# An empty script is a script with no events.
: >"$tmp/empty.txt"
"$T" "${sim[@]}" --script "$tmp/empty.txt" >/dev/null 2>"$tmp/err" || { echo "FAIL: empty script: $(cat "$tmp/err")"; failures=$((failures + 1)); }

# A yank to the edge of the allowed coordinates keeps every position finite, torn or not: the
# tender preset for 200 ticks without contact, then with its contact (whose hand runs 32 substeps a
# tick while it drags) for 4.
printf '0 grab particle 1535\n1 move 999999 999999 -999999\n' >"$tmp/edge.txt"
for case in "2.5 0 200" "0 0 200" "2.5 0.5 4" "0 0.5 4"; do
  read -r tear contact ticks <<<"$case"
  "$T" sim --backend cpu --ticks "$ticks" --set tear_factor="$tear" --set contact_factor="$contact" --script "$tmp/edge.txt" \
    --stats "$tmp/edge.json" >/dev/null &&
    python3 -c "import json,sys; s=json.load(open(sys.argv[1])); assert s['nan_count']==0, s" "$tmp/edge.json" &&
    echo "ok: yank to 999999 with tear_factor=$tear, contact_factor=$contact stays finite" ||
    { echo "FAIL: yank to 999999 with tear_factor=$tear, contact_factor=$contact"; failures=$((failures + 1)); }
done

# A write that fails (the file-size limit) exits 2, keeps the earlier good file and leaves no
# temporary file; so does a run killed while it writes.
"$T" sim --backend cpu --ticks 2 --out "$tmp/keep.ply" --stats "$tmp/keep.json" >/dev/null
cp "$tmp/keep.ply" "$tmp/keep.orig"
(ulimit -f 8; exec "$T" sim --backend cpu --ticks 2 --set cols=64 --set rows=64 --out "$tmp/keep.ply") >/dev/null 2>"$tmp/err"
rc=$?
if [ "$rc" -ne 2 ] || [ "$(wc -l <"$tmp/err")" -ne 1 ] || ! cmp -s "$tmp/keep.ply" "$tmp/keep.orig"; then
  echo "FAIL: over the file-size limit -> exit $rc: $(cat "$tmp/err")"; failures=$((failures + 1))
else
  echo "ok: over the file-size limit -> $(cat "$tmp/err"), earlier file intact"
fi
ls -A "$tmp" | grep -q '\.tmp\.' && { echo "FAIL: a temporary file was left"; failures=$((failures + 1)); }
"$T" sim --backend cpu --ticks 1 --set cols=700 --set rows=700 --set threads=1 --out "$tmp/keep.ply" >/dev/null 2>&1 &
victim=$!
sleep 1.5
kill -9 "$victim" 2>/dev/null
wait "$victim" 2>/dev/null
size=$(stat -c %s "$tmp/keep.ply")
if cmp -s "$tmp/keep.ply" "$tmp/keep.orig" ||
   python3 -c "import sys; d=open(sys.argv[1],'rb').read(); h=d.split(b'end_header\n')[0].decode(); v=int(h.split('element vertex ')[1].split()[0]); f=int(h.split('element face ')[1].split()[0]); assert len(d)==len(h)+11+12*v+13*f" "$tmp/keep.ply"; then
  echo "ok: a run killed while writing leaves the earlier file or the whole new one"
else
  echo "FAIL: a killed run left a fragment ($size bytes)"; failures=$((failures + 1))
fi

# A good run writes stats and a PLY that matches them (the seeds' cloth: contact's stats are the
# fast crumple's below).
printf '# yank a corner\n0 grab particle 1535\n1 move 4 -4 6\n20 release\n' >"$tmp/yank.txt"
if "$T" sim --backend cpu "${cloth[@]}" --ticks 30 --script "$tmp/yank.txt" --stats "$tmp/s.json" --out "$tmp/s.ply" >"$tmp/out"; then
  python3 - "$tmp/s.json" "$tmp/s.ply" <<'PY' || failures=$((failures + 1))
import json, sys
s = json.load(open(sys.argv[1]))
for k in ["particles", "constraints", "colors", "torn", "triangles", "ticks", "ms_per_tick", "state_hash",
          "bbox_min", "bbox_max", "max_stretch", "nan_count", "pairs"]:
    assert k in s, k
assert s["particles"] == 1536 and s["ticks"] == 30 and s["nan_count"] == 0, s
assert isinstance(s["pairs"], int) and s["pairs"] >= 0, s["pairs"]  # the exact judge of self-intersection
head = open(sys.argv[2], "rb").read(400).split(b"end_header")[0].decode()
assert "element vertex 1536" in head and f"element face {s['triangles']}" in head, head
print("ok: stats and PLY agree:", s["triangles"], "triangles,", s["torn"], "torn")
PY
else
  echo "FAIL: good sim run exited $?"; failures=$((failures + 1))
fi

"$T" --help >/dev/null && "$T" --version | grep -q '^tender ' || { echo "FAIL: --help/--version"; failures=$((failures + 1)); }

# The examples' crumples, last: under ASan (TENDER_SANITIZED) they are left to the unsanitized run,
# whose subject they are; their code runs under ASan in the Hand and Contact tests.
if [ -n "${TENDER_SANITIZED:-}" ]; then
  echo "$failures failed (the examples' crumples: in the unsanitized run)"
  [ "$failures" -eq 0 ]
  exit
fi

# The example of the hand (examples/hand_crumple.txt, as its comment runs it): the ball in the hand
hand=(sim --backend cpu --preset crumple --set tilt=90 --set pins=none --set wind=off --set floor_y=-3
  --set top_y=-2.925 --script "$(dirname "$0")/../../examples/hand_crumple.txt" --ticks 45 --stats "$tmp/hand.json")
if "$T" "${hand[@]}" >/dev/null; then
  python3 - "$tmp/hand.json" <<'PY' || failures=$((failures + 1))
import json, sys
s = json.load(open(sys.argv[1]))
size = [s["bbox_max"][k] - s["bbox_min"][k] for k in range(3)]
assert max(size) < 4.5 and s["nan_count"] == 0, size  # the 5.9 x 8.9 sheet: a ball in the hand, half its length
print("ok: the hand's example crumples the sheet to", ["%.2f" % v for v in size], "with", s["pairs"], "pairs")
PY
else
  echo "FAIL: the hand's example exited $?"; failures=$((failures + 1))
fi

# The fast crumple (examples/fast_crumple.txt, as its comment runs it): through itself with the
# contact turned off, never with the preset's, and the stats count the contacts
fast=(sim --backend cpu --preset crumple --set tilt=90 --set pins=none --set wind=off --set floor_y=-3
  --set top_y=-2.925 --script "$(dirname "$0")/../../examples/fast_crumple.txt" --ticks 20)
if "$T" "${fast[@]}" --set contact_factor=0 --stats "$tmp/loose.json" >/dev/null &&
  "$T" "${fast[@]}" --stats "$tmp/contact.json" >/dev/null; then
  python3 - "$tmp/loose.json" "$tmp/contact.json" <<'PY' || failures=$((failures + 1))
import json, sys
loose, contact = (json.load(open(f)) for f in sys.argv[1:3])
assert loose["pairs"] > 0 and "contacts" not in loose, loose
assert contact["pairs"] == 0 and contact["contacts"] > 0 and contact["nan_count"] == 0, contact
print("ok: the fast crumple:", loose["pairs"], "pairs without contact, 0 with,", contact["contacts"], "contacts")
PY
else
  echo "FAIL: the fast crumple's example exited $?"; failures=$((failures + 1))
fi

echo "$failures failed"
[ "$failures" -eq 0 ]
