#!/usr/bin/env bash
# `cpack -G DEB` of the build makes tender_<version>_<arch>.deb: its control lists the Debian
# packages the programs need, and it holds the programs, man pages, desktop entry and icons.
# Exit 77 (skipped) without cpack or dpkg-deb.
set -uo pipefail
B=${TENDER_BUILD_DIR:?}
VERSION=${TENDER_VERSION:?}
command -v cpack >/dev/null && command -v dpkg-deb >/dev/null || { echo "package_test: no cpack or dpkg-deb"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

if ! cpack -G DEB -B "$tmp" --config "$B/CPackConfig.cmake" >"$tmp/log" 2>&1; then
  cat "$tmp/log"
  echo "FAIL: cpack -G DEB"
  exit 1
fi
deb=$(compgen -G "$tmp/tender_${VERSION}_*.deb" | head -1)
[ -n "$deb" ] || { ls "$tmp"; echo "FAIL: no tender_${VERSION}_*.deb"; exit 1; }
dpkg-deb -I "$deb" >"$tmp/info" || fail "dpkg-deb -I"
grep -qx ' Package: tender' "$tmp/info" || fail "Package is not tender"
grep -qx " Version: $VERSION" "$tmp/info" || fail "Version is not $VERSION"
grep -q '^ Maintainer: .' "$tmp/info" || fail "no Maintainer"
depends=$(grep '^ Depends:' "$tmp/info")
want=(libc6 libstdc++6 fonts-dejavu-core)
[ "${TENDER_VULKAN:-0}" = 1 ] && want+=(libvulkan1 libfreetype6)
names=$(sed 's/^ Depends://' <<<"$depends" | tr ',' '\n' | awk '{print $1}')
for d in "${want[@]}"; do
  grep -qxF "$d" <<<"$names" || fail "Depends lacks $d: $depends"
done
grep -q '^ Recommends:.*mesa-vulkan-drivers' "$tmp/info" || fail "mesa-vulkan-drivers is not recommended"
dpkg-deb -c "$deb" >"$tmp/files" || fail "dpkg-deb -c"
for f in usr/bin/tender usr/share/applications/tender.desktop usr/share/icons/hicolor/48x48/apps/tender.png; do
  grep -q " \./$f\$" "$tmp/files" || fail "the package lacks /$f"
done
if [ "${TENDER_HELP2MAN:-0}" = 1 ]; then
  grep -q ' \./usr/share/man/man1/tender\.1' "$tmp/files" || fail "the package lacks the man page"
fi
if [ "$failures" -ne 0 ]; then
  cat "$tmp/info"
  exit 1
fi
echo "package_test: ok: $(basename "$deb")"
echo "$depends"
