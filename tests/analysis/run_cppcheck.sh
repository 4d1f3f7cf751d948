#!/bin/sh
# run_cppcheck.sh BUILD_DIR SOURCE_DIR [DIR...]
#   cppcheck over the translation units of BUILD_DIR/compile_commands.json under
#   SOURCE_DIR/DIR (default lib can io desk tools firmware host_sim), with the suppressions of cppcheck-suppressions.txt
#   (each justified there). Checks: warning, style, performance, portability, inconclusive
#   included. Exit 1 on any finding.
set -eu
build=$1
src=$2
shift 2
[ $# -gt 0 ] || set -- lib can io desk tools firmware host_sim
here=$(cd "$(dirname "$0")" && pwd)
db=$build/compile_commands.json
[ -f "$db" ] || { echo "run_cppcheck.sh: no $db (configure first)" >&2; exit 2; }
filters=""
for d in "$@"; do
  filters="$filters --file-filter=$(cd "$src/$d" && pwd)/*"
done
out=$build/cppcheck.log
set +e
# shellcheck disable=SC2086 # word splitting intended: one option per directory
cppcheck --project="$db" $filters --enable=warning,style,performance,portability \
  --inconclusive --std=c11 --platform=unix64 --library=posix --inline-suppr \
  --suppressions-list="$here/cppcheck-suppressions.txt" --error-exitcode=1 --quiet \
  -j "$(nproc)" --template='{file}:{line}: {severity}: {message} [{id}]' >"$out" 2>&1
rc=$?
set -e
if [ "$rc" -ne 0 ] || [ -s "$out" ]; then
  cat "$out"
  echo "cppcheck: findings under $* (exit $rc)"
  exit 1
fi
echo "cppcheck: $*: no findings"
