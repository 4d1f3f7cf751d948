#!/bin/sh
# run_clang_format.sh SOURCE_DIR
#   Every C and C++ file of the repository formatted as .clang-format says (clang-format
#   --dry-run --Werror): lib, can, io, desk, tools, firmware, host_sim, python, tests, bench, examples.
#   Exit 1 naming the files that differ, with the first lines clang-format would change;
#   77 (skipped, with the reason) for a clang-format other than the major version the style
#   was written with: versions format the same file differently.
#   To format: clang-format -i --style=file FILE... (Debian bookworm's clang-format).
set -eu
src=$1
want=14
version=$(clang-format --version | sed -n 's/.*clang-format version \([0-9][0-9]*\)\..*/\1/p')
if [ "$version" != "$want" ]; then
  echo "clang_format: skipped: clang-format $version, not $want (the version .clang-format is checked with)"
  exit 77
fi
cd "$src"
files=$(find lib can io desk tools firmware host_sim python tests bench examples \
          \( -name build -o -name _deps -o -name .venv -o -name 'unity' \) -prune -o \
          -type f \( -name '*.c' -o -name '*.h' -o -name '*.cc' -o -name '*.cpp' \) -print |
        sort)
bad=0
for f in $files; do
  if ! clang-format --style=file --dry-run --Werror "$f" >/dev/null 2>&1; then
    echo "$f: not formatted as .clang-format says; clang-format would change:"
    clang-format --style=file "$f" | diff "$f" - | head -8
    bad=$((bad + 1))
  fi
done
n=$(echo "$files" | wc -l)
if [ "$bad" -ne 0 ]; then
  echo "clang_format: $bad of $n files differ (clang-format -i --style=file FILE formats one)"
  exit 1
fi
echo "clang_format: $n files as .clang-format says"
