#!/usr/bin/env bash
# Faults and hostile input against the newer commands (sweep, sweep-merge, preset files, frames,
# diff's planted ULP, the demo's headless session, tender-bench): one line `tender: error: ...` and
# exit 2 every time, fast, never a hang, a crash, unbounded memory or a lost output.
set -u
. "$(dirname "$0")/lib.sh"
B=${TENDER_BENCH:?set TENDER_BENCH to the tender-bench binary}
PY=${PYTHON:-python3}
cd "$tmp" || exit 1 # a headless `tender` writes tender.png here
small=(--backend cpu --set cols=8 --set rows=8)

# expect_msg PATTERN ARGS...: as expect_bad, within 20 s and 4 GB of address space, and the line
# matches PATTERN (grep -E) and holds nothing but printable characters.
expect_msg() {
  local pattern=$1 rc lines
  shift
  (ulimit -v 4000000; exec timeout -s KILL 20 "$T" "$@") >"$tmp/out" 2>"$tmp/err"
  rc=$?
  lines=$(wc -l <"$tmp/err")
  if [ "$rc" -ne 2 ] || [ "$lines" -ne 1 ] || ! grep -q '^tender: error: ' "$tmp/err"; then
    fail "tender $* -> exit $rc, $lines stderr lines: $(head -c 400 "$tmp/err")"
  elif ! grep -Eq -- "$pattern" "$tmp/err"; then
    fail "tender $* -> '$(cat "$tmp/err")' does not say /$pattern/"
  elif LC_ALL=C grep -q '[^[:print:]]' "$tmp/err"; then
    fail "tender $* -> unprintable bytes in '$(cat -v "$tmp/err")'"
  else
    echo "ok: tender $* -> $(cat "$tmp/err")"
  fi
}
# expect_full PROGRAM ARGS...: with standard output on a full disk, exit 2 and one error line
# (tender-bench also reports its progress on stderr).
expect_full() {
  timeout -s KILL 60 "$@" >/dev/full 2>"$tmp/err"
  local rc=$?
  if [ "$rc" -ne 2 ] || [ "$(grep -c ': error: ' "$tmp/err")" -ne 1 ] ||
    ! tail -1 "$tmp/err" | grep -q '^tender[-a-z]*: error: .*standard output'; then
    fail "$* >/dev/full -> exit $rc: $(cat "$tmp/err")"
  else
    echo "ok: $* >/dev/full -> $(cat "$tmp/err")"
  fi
}
no_temps() { # FOLDER: no temporary file of an output is left there
  ! find "$1" -name '.*.tmp.*' | grep -q . || fail "temporary files left in $1: $(find "$1" -name '.*.tmp.*')"
}

# 3, 4, 10. Input files: a device, a FIFO with no writer, a folder, a huge sparse file.
mkfifo "$tmp/fifo"
truncate -s 2G "$tmp/huge"
printf '0 release\n' >"$tmp/ok.txt"
mkdir -p "$tmp/shard"
for f in /dev/zero "$tmp/fifo"; do
  expect_msg "not a regular file" sim "${small[@]}" --ticks 1 --script "$f"
  expect_msg "not a regular file" sweep "${small[@]}" --ticks 1 --vary damping=0.9 --out "$tmp/sw" --script "$f"
  expect_msg "not a regular file" render --backend cpu --ticks 1 --script "$f"
  expect_msg "not a regular file" --backend cpu --replay "$f"
  expect_msg "not a regular file" sim --preset-file "$f" --ticks 1
done
expect_msg "larger than" sim "${small[@]}" --ticks 1 --script "$tmp/huge"
expect_msg "larger than" --backend cpu --replay "$tmp/huge"
expect_msg "larger than" sim --preset-file "$tmp/huge" --ticks 1

# A sweep in two shards, merged, then broken in every way a merge must notice.
"$T" sweep "${small[@]}" --vary damping=0.9,0.95,0.99 --ticks 2 --shard 0/2 --out "$tmp/s0" >/dev/null &&
  "$T" sweep "${small[@]}" --vary damping=0.9,0.95,0.99 --ticks 2 --shard 1/2 --out "$tmp/s1" >/dev/null &&
  "$T" sweep-merge "$tmp/s0" "$tmp/s1" --out "$tmp/merged" >/dev/null || fail "a sweep in two shards"
broken() { # NAME: a copy of shard 1 to break
  rm -rf "$tmp/$1"
  cp -r "$tmp/s1" "$tmp/$1"
}
for f in sheets.jsonl sweep.json; do
  for bad in fifo huge folder; do
    broken b
    rm "$tmp/b/$f"
    case $bad in
    fifo) mkfifo "$tmp/b/$f" ;;
    huge) truncate -s 2G "$tmp/b/$f" ;;
    folder) mkdir "$tmp/b/$f" ;;
    esac
    expect_msg "$f" sweep-merge "$tmp/s0" "$tmp/b" --out "$tmp/m"
  done
done
# 5. Every line is checked against the sweep's definition.
broken b
sed -i 's/"damping":0.95/"damping":0.5/' "$tmp/b/sheets.jsonl"
expect_msg "values" sweep-merge "$tmp/s0" "$tmp/b" --out "$tmp/m"
broken b
sed -i 's/"state_hash":"[0-9a-f]*"/"state_hash":"zz"/' "$tmp/b/sheets.jsonl"
expect_msg "state_hash" sweep-merge "$tmp/s0" "$tmp/b" --out "$tmp/m"
broken b
rm -rf "$tmp/a"
cp -r "$tmp/s0" "$tmp/a"
grep '"index":0,' "$tmp/s0/sheets.jsonl" >>"$tmp/b/sheets.jsonl"
grep -v '"index":0,' "$tmp/s0/sheets.jsonl" >"$tmp/a/sheets.jsonl"
expect_msg "shard" sweep-merge "$tmp/a" "$tmp/b" --out "$tmp/m"
[ -e "$tmp/m" ] && [ -n "$(ls -A "$tmp/m")" ] && fail "a refused merge wrote $(ls "$tmp/m")"
expect_msg "folder" sweep-merge --out "$tmp/m"

# 6. A full standard output is an error.
expect_full "$T" sim "${small[@]}" --ticks 2
expect_full "$T" sweep "${small[@]}" --vary damping=0.9 --ticks 1 --out "$tmp/full"
expect_full "$T" diff --set cols=8 --set rows=8 --ticks 2 --a cpu --b cpu
expect_full "$T" presets
expect_full "$T" devices
expect_full "$T" --help
expect_full "$B" --backends cpu --sizes 8x8 --ticks 1 --warmup 0 --no-peak

# 7. An empty value is bad input, never "not given".
expect_msg "empty" render --backend cpu --ticks 1 --video ""
[ -e tender.png ] && fail "--video '' wrote tender.png"
for opt in --seed --samples --batch --shard; do
  expect_msg "empty" sweep "${small[@]}" --vary damping=0.9 --ticks 1 --out "$tmp/e" "$opt" ""
done
expect_msg "empty" sim "${small[@]}" --ticks 2 --out "$tmp/e.glb" --frames-every ""
"$B" --backends cpu --sizes 8x8 --ticks 1 --batch "" >"$tmp/out" 2>"$tmp/err"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ] && grep -q '^tender-bench: error: --batch: the value is empty' "$tmp/err" ||
  fail "tender-bench --batch '' -> exit $rc: $(cat "$tmp/err")"
# The grid is --sizes': a --set of cols or rows beside it would run a sheet the table does not name.
for key in cols rows; do
  "$B" --backends cpu --sizes 8x8 --ticks 1 --set "$key=1" >"$tmp/out" 2>"$tmp/err"
  rc=$?
  [ "$rc" -eq 2 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ] &&
    grep -q "^tender-bench: error: --set $key: the grid is set by --sizes" "$tmp/err" ||
    fail "tender-bench --sizes 8x8 --set $key=1 -> exit $rc: $(cat "$tmp/err")"
done

# 8. Ctrl-C or SIGTERM: one line, exit 2, no output and no temporary file left.
# (Python restores SIGINT's default, which a background job of a script ignores.)
for sig in INT TERM; do
  for cmd in "sim --backend cpu --set cols=64 --set rows=64 --ticks 100000000 --stats $tmp/int/s.json" \
    "sweep --backend cpu --set cols=32 --set rows=32 --vary damping=0.9,0.95 --ticks 100000000 --out $tmp/int"; do
    mkdir -p "$tmp/int"
    # shellcheck disable=SC2086
    "$PY" -c 'import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); os.execv(sys.argv[1], sys.argv[1:])' \
      "$T" $cmd >/dev/null 2>"$tmp/err" &
    pid=$!
    sleep 2
    kill -s "$sig" "$pid"
    wait "$pid"
    rc=$?
    if [ "$rc" -ne 2 ] || [ "$(wc -l <"$tmp/err")" -ne 1 ] || ! grep -q '^tender: error: ' "$tmp/err"; then
      fail "SIG$sig on tender ${cmd%% *} -> exit $rc: $(cat "$tmp/err")"
    else
      echo "ok: SIG$sig on tender ${cmd%% *} -> $(cat "$tmp/err")"
    fi
    [ -z "$(ls -A "$tmp/int")" ] || fail "SIG$sig on tender ${cmd%% *} left $(ls -A "$tmp/int")"
    rm -rf "$tmp/int"
  done
done

# 9. The frame caps count the final frame.
expect_msg "1000 frames" sim "${small[@]}" --ticks 2998 --frames-every 3 --out "$tmp/anim.glb"
mkdir -p "$tmp/seq"
expect_msg "100000 files" sim "${small[@]}" --ticks 299998 --frames-every 3 --out "$tmp/seq/"

# 11. Non-finite numbers are out of every range.
expect_msg "ui-scale" --backend cpu --ui-scale nan
expect_msg "ui-scale" --backend cpu --ui-scale inf

# 13. Messages: one line of printable text, whatever the input held.
expect_msg "damping" sim "${small[@]}" --ticks 1 --set "damping=1
2"
printf '0 grab particle 5\n1 \377\376\001bad\n' >"$tmp/bytes.txt"
expect_msg "unknown event" --backend cpu --replay "$tmp/bytes.txt"
expect_msg "unknown event" sim "${small[@]}" --ticks 1 --script "$tmp/bytes.txt"
for closure in 2 -0.5 nan x ""; do
  printf '0 grab particle 5\n1 squeeze %s\n' "$closure" >"$tmp/squeeze.txt"
  expect_msg "line 2: squeeze" sim "${small[@]}" --ticks 1 --script "$tmp/squeeze.txt"
done
printf '{"wi\\u0000nd": true}' >"$tmp/nul.json"
expect_msg "wi.*nd'" sim --preset-file "$tmp/nul.json" --ticks 1
printf '{"cols": true}' >"$tmp/boolcols.json"
expect_msg "cols: expected a whole number, got true" sim --preset-file "$tmp/boolcols.json" --ticks 1
printf '{"cols": 18446744073709551617}' >"$tmp/bigcols.json"
expect_msg "18446744073709551617" sim --preset-file "$tmp/bigcols.json" --ticks 1
# Out of memory (here: of address space) is said in words; with less memory than the sheet needs,
# the run is refused before it starts.
(ulimit -v 1000000; exec "$T" sim --backend cpu --set threads=1 --set cols=2000 --set rows=2000 --ticks 1) \
  >/dev/null 2>"$tmp/err"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ] && grep -Eq 'error: (out of memory|.*MiB are available)' "$tmp/err" ||
  fail "out of memory -> exit $rc: $(cat "$tmp/err")"

# 14. Preset files: one rule for a value's type, no NUL, no key twice.
printf '{"wind": false}\0{"cols": 0}' >"$tmp/nulbyte.json"
expect_msg "NUL" sim --preset-file "$tmp/nulbyte.json" --ticks 1
printf '{"cols": 8, "cols": 9}' >"$tmp/twice.json"
expect_msg "cols.*twice" sim --preset-file "$tmp/twice.json" --ticks 1
printf '{"wind": 1}' >"$tmp/windnum.json"
expect_msg "wind: expected true or false, got 1" sim --preset-file "$tmp/windnum.json" --ticks 1
printf '{"cols": 8.0}' >"$tmp/float.json"
expect_msg "cols: expected a whole number, got 8.0" sim --preset-file "$tmp/float.json" --ticks 1

# 15. A planted ULP the run never reaches is refused.
for plant in 9:0:floor:3 0:4:floor:3 0:0:project.3.0:3 0:0:project.0.99:3 0:0:collide:3; do
  TENDER_TEST_PLANT_ULP=$plant expect_msg "TENDER_TEST_PLANT_ULP" diff --set cols=8 --set rows=8 --set substeps=4 \
    --set iterations=3 --set collision=off --ticks 5 --a cpu --b cpu
done

# 16. Stale temporary files of a killed run are cleaned; two shards never share a folder; a
# recording never replaces the script it replays.
mkdir -p "$tmp/frames"
"$T" sim --backend cpu --set cols=16 --set rows=16 --ticks 50000 --frames-every 1 --out "$tmp/frames/" \
  >/dev/null 2>&1 &
pid=$!
for _ in $(seq 300); do # killed once it has staged frames (within 30 s)
  find "$tmp/frames" -name '.*.tmp.*' | grep -q . && break
  sleep 0.1
done
kill -9 "$pid"
wait "$pid" 2>/dev/null
find "$tmp/frames" -name '.*.tmp.*' | grep -q . || fail "the killed run left no temporary file to clean (test setup)"
"$T" sim --backend cpu --set cols=16 --set rows=16 --ticks 2 --frames-every 1 --out "$tmp/frames/" >/dev/null ||
  fail "a sequence after a killed run"
no_temps "$tmp/frames"
expect_msg "shard 0/2" sweep "${small[@]}" --vary damping=0.9,0.95,0.99 --ticks 2 --shard 1/2 --out "$tmp/s0"
cmp -s "$tmp/s0/sheets.jsonl" <(grep -v '"index":1,' "$tmp/merged/sheets.jsonl") || fail "shard 0's lines changed"
cp "$tmp/ok.txt" "$tmp/rec.txt"
expect_msg "same file" --backend cpu --replay "$tmp/rec.txt" --record "$tmp/rec.txt"
cmp -s "$tmp/ok.txt" "$tmp/rec.txt" || fail "--record replaced the --replay script"
expect_msg "same file" sim "${small[@]}" --ticks 1 --script "$tmp/rec.txt" --stats "$tmp/rec.txt"
cmp -s "$tmp/ok.txt" "$tmp/rec.txt" || fail "--stats replaced the --script"
no_temps "$tmp"

[ "$failures" -eq 0 ] && echo "ok: hostile input and faults"
exit $((failures > 0))
