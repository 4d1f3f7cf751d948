#!/bin/sh
# run_fuzz.sh FUZZER SECONDS WORKDIR INPUT_DIR... [-libfuzzer_flag...]
#   Fuzzes for SECONDS. The input directories (seed corpus, regressions) are only read:
#   libFuzzer writes new inputs into its first corpus directory, WORKDIR/corpus, made
#   empty here. On a crash, leak, timeout or out-of-memory: prints the end of the log and
#   the saved input, exits 1. Otherwise prints one line:
#     fuzz_csv: 123456 executions in 10 s (12345/s), coverage 789, 12 new inputs
set -eu
if [ $# -lt 4 ]; then
  echo "usage: $0 FUZZER SECONDS WORKDIR INPUT_DIR... [-flag=value...]" >&2
  exit 2
fi
fuzzer=$1
secs=$2
work=$3
shift 3
name=$(basename "$fuzzer")
rm -rf "$work"
mkdir -p "$work/corpus" "$work/tmp"
# Targets that need files put them under TMPDIR: keep them in the work directory.
TMPDIR=$work/tmp
export TMPDIR
UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export UBSAN_OPTIONS
set +e
"$fuzzer" -max_total_time="$secs" -rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=10 \
  -print_final_stats=1 -artifact_prefix="$work/" "$work/corpus" "$@" >"$work/log" 2>&1
rc=$?
set -e
execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log" | tail -n 1)
cov=$(grep -Eo 'cov: [0-9]+' "$work/log" | tail -n 1 | cut -d' ' -f2)
new=$(find "$work/corpus" -type f | wc -l | tr -d ' ')
artifacts=$(find "$work" -maxdepth 1 -type f \
  \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \
     -o -name 'slow-unit-*' \) | sort)
if [ "$rc" -ne 0 ] || [ -n "$artifacts" ] || [ -z "$execs" ]; then
  tail -n 80 "$work/log"
  echo
  echo "$name: FUZZING FOUND A FAILURE (exit $rc). Input(s):"
  for a in $artifacts; do
    echo "  $a"
  done
  echo "Replay: $fuzzer <input>. Keep it as a regression once fixed:"
  echo "  cp <input> tests/fuzz/regressions/${name#fuzz_}/<what-it-was>"
  exit 1
fi
rate=$((execs / (secs > 0 ? secs : 1)))
echo "$name: $execs executions in $secs s ($rate/s), coverage ${cov:-?}, $new new inputs"
