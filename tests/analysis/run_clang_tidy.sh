#!/bin/sh
# run_clang_tidy.sh BUILD_DIR SOURCE_DIR [DIR...]
#   clang-tidy (configuration: SOURCE_DIR/.clang-tidy, and any .clang-tidy below it) over
#   every translation unit of BUILD_DIR/compile_commands.json under SOURCE_DIR/DIR (default
#   lib can io desk tools firmware host_sim), in parallel. Prints every finding; exit 1 if there is any, 0 otherwise.
set -eu
build=$1
src=$2
shift 2
[ $# -gt 0 ] || set -- lib can io desk tools firmware host_sim
db=$build/compile_commands.json
[ -f "$db" ] || { echo "run_clang_tidy.sh: no $db (configure first)" >&2; exit 2; }
out=$build/clang-tidy.log
files=$(python3 - "$db" "$src" "$@" <<'PY'
import json, os, sys
db, src, dirs = sys.argv[1], os.path.realpath(sys.argv[2]), sys.argv[3:]
roots = [os.path.join(src, d) + os.sep for d in dirs]
seen = set()
for e in json.load(open(db)):
    f = os.path.realpath(os.path.join(e['directory'], e['file']))
    if any(f.startswith(r) for r in roots) and f not in seen:
        seen.add(f)
        print(f)
PY
)
[ -n "$files" ] || { echo "run_clang_tidy.sh: no translation unit under $*" >&2; exit 2; }
n=$(printf '%s\n' "$files" | wc -l | tr -d ' ')
set +e
printf '%s\n' "$files" | xargs -P "$(nproc)" -n 1 clang-tidy -p "$build" --quiet >"$out" 2>&1
rc=$?
set -e
# clang-tidy writes "N warnings generated." for diagnostics it filtered out: not findings.
findings=$(grep -E '(warning|error): ' "$out" || true)
if [ "$rc" -ne 0 ] || [ -n "$findings" ]; then
  grep -v -E '^[0-9]+ warnings? (and [0-9]+ errors? )?generated\.$' "$out" || true
  echo "clang-tidy: $(printf '%s\n' "$findings" | grep -c . || true) finding(s) in $n files (exit $rc)"
  exit 1
fi
echo "clang-tidy: $n files under $*, no findings"
