#!/bin/sh
# params_out_check.sh FW MACHINE SCENARIO - dhcal-fw --params-out (sim port): the file holds
# the parameters of the JSON result, one "name value" line each, and replaces an earlier
# file whole; a file that cannot be written is named on standard error and the run exits 1.
FW=$1 MACHINE=$2 SCENARIO=$3
dir=$(mktemp -d) || exit 1
trap 'rm -rf "$dir"' EXIT
fail=0
printf 'an earlier calibration\n' >"$dir/params.txt"
"$FW" --port sim --machine "$MACHINE" --scenario "$SCENARIO" --samples 20 \
    --params-out "$dir/params.txt" >"$dir/out.json" 2>"$dir/err.txt"
rc=$?
[ "$rc" = 0 ] || { echo "params_out_check: exit $rc, expected 0"; cat "$dir/err.txt"; fail=1; }
python3 - "$dir/out.json" "$dir/params.txt" <<'PY' || fail=1
import json, sys
result = json.load(open(sys.argv[1]))["params"]
rows = [line.split() for line in open(sys.argv[2])]
written = {name: float(value) for name, value in rows}
if len(rows) != len(result) or written != result:
    sys.exit("params_out_check: --params-out differs from the JSON result's params")
print("params_out_check: %d parameters, equal to the JSON result" % len(rows))
PY
ls "$dir" | grep -q '\.tmp' && { echo "params_out_check: a temporary file was left"; fail=1; }
"$FW" --port sim --machine "$MACHINE" --scenario "$SCENARIO" --samples 20 \
    --params-out "$dir/missing/params.txt" >/dev/null 2>"$dir/err.txt"
rc=$?
[ "$rc" = 1 ] || { echo "params_out_check: unwritable file: exit $rc, expected 1"; fail=1; }
grep -q -- "--params-out: $dir/missing/params.txt" "$dir/err.txt" ||
    { echo "params_out_check: the unwritable file is not named"; cat "$dir/err.txt"; fail=1; }
exit "$fail"
