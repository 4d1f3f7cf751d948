#!/usr/bin/env bash
# CMAKE_CROSSCOMPILING_EMULATOR of the cortex-m4 preset: runs a bare-metal ELF on QEMU's
# mps2-an386 (Cortex-M4F) and exits with the program's own status, which the runtime in
# tests/target/ hands over through semihosting SYS_EXIT_EXTENDED.
# Usage: qemu-mps2-an386.sh <elf> [args]   (args reach the guest as SYS_GET_CMDLINE text)
# DHCAL_QEMU_TIMEOUT (seconds, default 600): a hung guest fails with 124, not forever.
# DHCAL_QEMU_OPTS: more QEMU options, split at spaces (e.g. "-icount shift=0", which makes the
# board's timers count executed instructions: tests/target/twin/twin_target.c).
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: $0 <elf> [args]" >&2; exit 2; }
elf=$1
shift
append=()
extra=()
[ -z "${DHCAL_QEMU_OPTS:-}" ] || read -r -a extra <<<"$DHCAL_QEMU_OPTS"
[ $# -eq 0 ] || append=(-append "$*")
# stdin from /dev/null: -nographic would otherwise put a terminal into raw mode, and a killed
# QEMU leaves it there.
exec timeout --kill-after=5 "${DHCAL_QEMU_TIMEOUT:-600}" \
  qemu-system-arm -M mps2-an386 -nographic -monitor none \
  -semihosting-config enable=on,target=native "${extra[@]}" -kernel "$elf" "${append[@]}" \
  </dev/null
