#!/bin/sh
# stop_check.sh FW MACHINE SCENARIO - dhcal-fw on the sim port, sent SIGTERM in the middle of
# its run, must stop: exit 1, fault "stopped", every simulated drive's last command 0 V
# (DAC code 2048), and say so on standard error.
FW=$1 MACHINE=$2 SCENARIO=$3
dir=$(mktemp -d) || exit 1
trap 'rm -rf "$dir"' EXIT
# 128 poses: about ten seconds of run, far more than the half second before the signal.
"$FW" --port sim --machine "$MACHINE" --scenario "$SCENARIO" --samples 128 \
    >"$dir/out.json" 2>"$dir/err.txt" &
pid=$!
sleep 0.5
kill -TERM "$pid"
wait "$pid"
rc=$?
cat "$dir/out.json" "$dir/err.txt"
fail=0
[ "$rc" = 1 ] || { echo "stop_check: exit $rc, expected 1"; fail=1; }
grep -q '"fault": *"stopped"' "$dir/out.json" || { echo "stop_check: fault is not 'stopped'"; fail=1; }
grep -q '"plant_dac": *\[2048, *2048, *2048\]' "$dir/out.json" ||
    { echo "stop_check: the drives' last commands are not 0 V (code 2048)"; fail=1; }
grep -q '"drive_v_after_fault": *\[0, *0, *0\]' "$dir/out.json" ||
    { echo "stop_check: the controller's last command is not 0 V"; fail=1; }
grep -q 'SIGTERM: drives commanded to 0 V and disabled' "$dir/err.txt" ||
    { echo "stop_check: no word of the stop on standard error"; fail=1; }
[ "$fail" = 0 ] && echo "stop_check: stopped on SIGTERM, drives at 0 V"
exit "$fail"
