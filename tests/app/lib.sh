# Shared by the command-line tests (sourced): `tmp`, a folder removed at exit; `fail MESSAGE`,
# which counts a failure; `expect_bad ARGS...`, which checks that `$T ARGS...` exits 2 with one
# line `tender: error: ...` on stderr. Vulkan runs on lavapipe unless VK_DRIVER_FILES says
# otherwise.
T=${TENDER:?set TENDER to the tender binary}
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
. "$(dirname "${BASH_SOURCE[0]}")/scenes.sh"
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

expect_bad() {
  "$T" "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$? lines
  lines=$(wc -l <"$tmp/err")
  if [ "$rc" -ne 2 ] || [ "$lines" -ne 1 ] || ! grep -q '^tender: error: ' "$tmp/err"; then
    fail "tender $* -> exit $rc, $lines stderr lines: $(cat "$tmp/err")"
  else
    echo "ok: tender $* -> $(cat "$tmp/err")"
  fi
}
