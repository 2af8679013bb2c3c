#!/usr/bin/env bash
# tender-spirv-rules, the build step of every simulation shader, refuses one that divides or takes
# a square root outside exact_math.h's correction, naming where (data/inexact_operations.comp.glsl);
# each simulation shader of the build passed the same step.
# usage: inexact_rule_test.sh TENDER-SPIRV-RULES BAD.spv
set -uo pipefail
rules=$1 bad=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$rules" "$bad" "$out/ruled.spv" 2>"$out/err"
rc=$?
cat "$out/err"
fail() { echo "FAIL: $*"; exit 1; }
[[ $rc == 2 ]] || fail "exit status $rc, expected 2"
[[ ! -e $out/ruled.spv && ! -e $out/ruled.spv.tmp ]] || fail "a refused shader left an output"
grep -q "error: .*: in share: OpFDiv" "$out/err" || fail "the divide in share() is not named"
grep -q "error: .*: in root: a call of deviceSqrt" "$out/err" || fail "the uncorrected sqrt in root() is not named"
[[ $(wc -l <"$out/err") == 2 ]] || fail "simDiv and simSqrt are the correction's own calls, not refused"
echo PASS
