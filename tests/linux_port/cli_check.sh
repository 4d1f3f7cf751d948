#!/bin/sh
# cli_check.sh RC REGEX COMMAND... - COMMAND must exit with RC and print a line matching
# REGEX (stdout or stderr): the clear errors dhcal-fw and dhcal-sim promise.
want_rc=$1 want_re=$2
shift 2
out=$("$@" 2>&1)
rc=$?
printf '%s\n' "$out"
if [ "$rc" != "$want_rc" ]; then
    echo "cli_check: exit $rc, expected $want_rc"
    exit 1
fi
printf '%s\n' "$out" | grep -Eq -- "$want_re" || { echo "cli_check: no line matches '$want_re'"; exit 1; }
echo "cli_check: exit $rc and '$want_re' as expected"
