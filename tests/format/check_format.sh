#!/usr/bin/env bash
# Checks every C++ source of the project against the top-level .clang-format and lists the files
# that differ (the first lines of each difference). `make format` rewrites them in place.
# Usage: check_format.sh SOURCE_DIR [--fix]
set -euo pipefail
src=$1 fix=${2:-}
tool=$(command -v clang-format-14 || command -v clang-format || true)
if [ -z "$tool" ]; then
  echo "clang-format not found (Debian: clang-format; make deps installs it)" >&2
  exit 1
fi
cd "$src"
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files -- '*.cpp' '*.hpp' '*.h')
else
  mapfile -t files < <(find . -path ./build -prune -o -path './build-*' -prune -o \
    \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) -print | sed 's|^\./||' | sort)
fi
if [ "$fix" = --fix ]; then
  "$tool" -i "${files[@]}"
  echo "formatted ${#files[@]} files"
  exit 0
fi
bad=0
for f in "${files[@]}"; do
  if ! diff -q "$f" <("$tool" "$f") >/dev/null; then
    bad=$((bad + 1))
    echo "not formatted: $f"
    diff -u "$f" <("$tool" "$f") | sed -n '3,12p' || true
  fi
done
if [ "$bad" -gt 0 ]; then
  echo "$bad of ${#files[@]} files differ from .clang-format: run 'make format'" >&2
  exit 1
fi
echo "all ${#files[@]} sources follow .clang-format"
