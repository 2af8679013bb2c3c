#!/usr/bin/env bash
# The progress bar of `tender sim`: nothing on stderr when it is not a terminal; on a terminal
# (a pty from util-linux's `script`), a line rewritten in place once the run has taken a second,
# erased at the end. Exit 77 (skipped) without `script`.
set -uo pipefail
. "$(dirname "$0")/lib.sh"
# About two and a half seconds of ticks on one CPU thread here (the seeds' cloth, without
# contact); longer under load is fine.
run=(sim --backend cpu "${cloth[@]}" --set threads=1 --set cols=64 --set rows=96 --ticks 500)

start=$(date +%s%N)
"$T" "${run[@]}" >"$tmp/out" 2>"$tmp/err" || { echo "FAIL: tender sim: $(cat "$tmp/err")"; exit 1; }
ms=$((($(date +%s%N) - start) / 1000000))
[ ! -s "$tmp/err" ] || { echo "FAIL: stderr is not a terminal but has: $(cat -v "$tmp/err")"; exit 1; }
grep -q 'state hash' "$tmp/out" || { echo "FAIL: no summary"; exit 1; }

command -v script >/dev/null || { echo "progress_test: no script (util-linux): the terminal case is skipped"; exit 77; }
cmd=$(printf '%q ' "$T" "${run[@]}")
start=$(date +%s%N)
script -qec "$cmd" /dev/null </dev/null >"$tmp/tty" 2>&1 || { echo "FAIL: under script: $(cat -v "$tmp/tty")"; exit 1; }
tty_ms=$((($(date +%s%N) - start) / 1000000))
grep -q 'state hash' "$tmp/tty" || { echo "FAIL: no summary on the terminal: $(cat -v "$tmp/tty")"; exit 1; }
if [ "$tty_ms" -lt 1300 ]; then
  echo "progress_test: the run took ${tty_ms} ms (under a second and a bit): no bar expected"
  grep -q 'tender sim: \[' "$tmp/tty" && { echo "FAIL: a bar for a short run"; exit 1; }
  exit 0
fi
grep -aq $'\rtender sim: \[[#-]*\] *[0-9]*% tick [0-9]* of 500, [0-9:]* left' "$tmp/tty" ||
  { echo "FAIL: no progress bar in ${tty_ms} ms: $(cat -v "$tmp/tty")"; exit 1; }
grep -aq $'\r\033\[K' "$tmp/tty" || { echo "FAIL: the bar is not erased: $(cat -v "$tmp/tty")"; exit 1; }
# The summary starts a line of its own, after the bar is erased.
grep -aq $'\033\[Ktender sim: preset' "$tmp/tty" || { echo "FAIL: summary not after the erased bar: $(cat -v "$tmp/tty")"; exit 1; }
echo "progress_test: ok (${ms} ms without a terminal, ${tty_ms} ms on one)"
