#!/usr/bin/env bash
# Formats the C++ sources (src, apps, python, tests, bench, fuzz) with clang-format-14 and the
# repository's .clang-format, in place.
#
#   bash scripts/format.sh           format every file in place
#   bash scripts/format.sh --check   change nothing; list the files that are not formatted and
#                                    exit 1 if there are any (for CI)
#
# Environment: CLANG_FORMAT, the clang-format to run (default clang-format-14: another version
# formats some constructs differently).
set -euo pipefail
cd "$(dirname "$0")/.."

clang_format="${CLANG_FORMAT:-clang-format-14}"
if ! command -v "$clang_format" > /dev/null; then
  echo "format: $clang_format not found (Debian package clang-format-14)" >&2
  exit 2
fi

check=0
case "${1:-}" in
  "") ;;
  --check) check=1 ;;
  *)
    echo "usage: bash scripts/format.sh [--check]" >&2
    exit 2
    ;;
esac

mapfile -t files < <(git ls-files --cached --others --exclude-standard -- src apps python tests bench fuzz | grep -E '\.(cpp|h|inl)$')

if [ "$check" = 0 ]; then
  "$clang_format" -i --style=file "${files[@]}"
  exit 0
fi

unformatted=()
for f in "${files[@]}"; do
  if ! "$clang_format" --dry-run -Werror --style=file "$f" > /dev/null 2>&1; then
    unformatted+=("$f")
  fi
done
if [ "${#unformatted[@]}" -gt 0 ]; then
  echo "format: ${#unformatted[@]} files are not formatted (bash scripts/format.sh formats them):" >&2
  printf '  %s\n' "${unformatted[@]}" >&2
  exit 1
fi
echo "format: all ${#files[@]} files are formatted"
