#!/usr/bin/env bash
# `cmake --install` into a temporary prefix: the installed programs run from there (no RPATH into
# the build tree), each has its man page (when help2man was found), the desktop entry is valid, the
# icons are PNGs of their sizes, and the Python module imports when one was built.
set -uo pipefail
B=${TENDER_BUILD_DIR:?TENDER_BUILD_DIR: the build folder}
VERSION=${TENDER_VERSION:?}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

p=$tmp/prefix
if ! cmake --install "$B" --prefix "$p" >"$tmp/log" 2>&1; then
  cat "$tmp/log"
  echo "FAIL: cmake --install $B --prefix $p"
  exit 1
fi

# The programs, run from the prefix (from /, with the build tree's folders nowhere on PATH).
[ -x "$p/bin/tender" ] || fail "bin/tender not installed"
for prog in "$p"/bin/*; do
  name=$(basename "$prog")
  out=$(cd / && env -u LD_LIBRARY_PATH "$prog" --version 2>&1) || fail "$name --version exits $?: $out"
  want="$name $VERSION"
  [ "$out" = "$want" ] || fail "$name --version prints '$out', not '$want'"
  (cd / && "$prog" --help >/dev/null 2>&1) || fail "$name --help fails"
done

# No installed ELF file looks for libraries in the build or source tree.
if command -v readelf >/dev/null; then
  while IFS= read -r -d '' f; do
    [ "$(head -c 4 "$f" | od -An -c | tr -d ' ')" = '177ELF' ] || continue
    paths=$(readelf -d "$f" 2>/dev/null | grep -E 'R(UN)?PATH' || true)
    if [ -n "$paths" ] && grep -qF -e "$B" -e "${TENDER_SOURCE_DIR:-/nonexistent}" <<<"$paths"; then
      fail "${f#"$p"/} has an RPATH into the build tree: $paths"
    fi
  done < <(find "$p" -type f -print0)
fi

# Man pages: one per program, written by help2man from --help and --version.
if [ "${TENDER_HELP2MAN:-0}" = 1 ]; then
  for prog in "$p"/bin/*; do
    name=$(basename "$prog")
    page=$p/share/man/man1/$name.1
    if [ ! -s "$page" ]; then
      fail "no man page share/man/man1/$name.1"
      continue
    fi
    grep -q '^\.TH ' "$page" || fail "$name.1 has no .TH line"
    grep -qF -- '\-\-version' "$page" || fail "$name.1 does not list --version"
    grep -qF "$B" "$page" && fail "$name.1 names the build tree"
  done
  grep -q 'sim' "$p/share/man/man1/tender.1" || fail "tender.1 does not name the sim command"
  if command -v man >/dev/null; then
    MANWIDTH=80 man -l "$p/share/man/man1/tender.1" 2>"$tmp/man.err" | grep -q 'receipt paper' ||
      fail "man -l tender.1 does not render: $(cat "$tmp/man.err")"
  fi
else
  echo "install_test: no help2man when configured: man pages not checked"
fi

# The desktop entry and the icon it names.
desktop=$p/share/applications/tender.desktop
if [ -f "$desktop" ]; then
  grep -qx 'Exec=tender' "$desktop" || fail "tender.desktop: Exec is not tender"
  grep -qx 'Icon=tender' "$desktop" || fail "tender.desktop: Icon is not tender"
  grep -qx 'Categories=Graphics;Science;Education;' "$desktop" || fail "tender.desktop: Categories"
  if command -v desktop-file-validate >/dev/null; then
    desktop-file-validate "$desktop" >"$tmp/dfv" 2>&1 || fail "desktop-file-validate: $(cat "$tmp/dfv")"
    grep -q 'error:' "$tmp/dfv" && fail "desktop-file-validate: $(cat "$tmp/dfv")"
  else
    echo "install_test: no desktop-file-validate: the entry is not validated"
  fi
else
  fail "share/applications/tender.desktop not installed"
fi
for size in 16 24 32 48 64 128 256; do
  png=$p/share/icons/hicolor/${size}x${size}/apps/tender.png
  if [ ! -s "$png" ]; then
    fail "no icon ${size}x${size}"
    continue
  fi
  # The PNG signature, then the IHDR's width and height (big-endian).
  [ "$(head -c 8 "$png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "${size}x${size} icon is not a PNG"
  wh=$(od -An -tu1 -j16 -N8 "$png" | awk '{print $1*16777216+$2*65536+$3*256+$4, $5*16777216+$6*65536+$7*256+$8}')
  [ "$wh" = "$size $size" ] || fail "${size}x${size} icon is $wh"
done

# The Python module, when one was built and installed.
pydir=""
for d in "$p"/lib/python3*/site-packages "$p"/lib/python3*/dist-packages "$p"/lib/python3/dist-packages \
  "$p"/local/lib/python3*/dist-packages; do
  if [ -e "$d/tender" ] || compgen -G "$d/tender*.so" >/dev/null || [ -e "$d/tender.py" ]; then
    pydir=$d
    break
  fi
done
if [ -n "$pydir" ]; then
  (cd / && PYTHONPATH="$pydir" python3 -c "import tender") >"$tmp/py" 2>&1 ||
    fail "PYTHONPATH=${pydir#"$p"/} python3 -c 'import tender': $(cat "$tmp/py")"
else
  echo "install_test: no Python module installed: not imported"
fi

if [ "$failures" -ne 0 ]; then
  echo "$failures failure(s)"
  exit 1
fi
echo "install_test: ok ($(find "$p" -type f | wc -l) files installed)"
