#!/bin/sh
# vm_run.sh - the linux-port test on real kernel devices: boots Debian's kernel under QEMU
# with an initramfs of busybox, dhcal-fw and dhcal-sim (and the shared libraries they
# use), and runs vm_init.sh's cases inside: the calibration run over vcan0 compared with
# the sim port's run on this host, a lost CAN frame, a bus timeout, GPIO quadrature on
# gpio-sim with and without a missed edge, the touch probe's switch on a gpio-sim line (active
# high and low, and silent), and configuration errors.
#
# usage: vm_run.sh --cache DIR --work DIR --fw dhcal-fw --sim dhcal-sim --machine M.json
#                  --scenario S.json [--can-check linux_can_check] [--samples N]
#                  [--fault-tick T] [--timeout S]
# M.json: the controller's machine file (self-contained: its model inline); S.json: the
# simulated arm dhcal-sim bus plays.
# Environment: DHCAL_VM_ACCEL=kvm tries KVM (default tcg: on these machines /dev/kvm is a
# software nested hypervisor on which stock kernels hang).
# Exit status: 0 every case passed, 1 a case failed or the VM did not finish, 77 the test
# cannot run here (reason printed; CTest reports it as skipped).
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
CACHE= WORK= FW= SIM= CAN_CHECK= MACHINE= SCENARIO= SAMPLES=20 FAULT_TICK=1500 TIMEOUT=600
while [ $# -gt 0 ]; do
    case $1 in
        --cache) CACHE=$2 ;;
        --work) WORK=$2 ;;
        --fw) FW=$2 ;;
        --sim) SIM=$2 ;;
        --can-check) CAN_CHECK=$2 ;;
        --machine) MACHINE=$2 ;;
        --scenario) SCENARIO=$2 ;;
        --samples) SAMPLES=$2 ;;
        --fault-tick) FAULT_TICK=$2 ;;
        --timeout) TIMEOUT=$2 ;;
        *) echo "vm_run: unknown option $1" >&2; exit 2 ;;
    esac
    shift 2
done
[ -n "$CACHE" ] && [ -n "$WORK" ] && [ -x "$FW" ] && [ -x "$SIM" ] && [ -f "$MACHINE" ] &&
    [ -f "$SCENARIO" ] ||
    { echo "vm_run: needs --cache --work --fw --sim --machine --scenario" >&2; exit 2; }
skip() { echo "vm_run: SKIP: $*"; exit 77; }
T0=$(date +%s)

command -v qemu-system-x86_64 >/dev/null 2>&1 ||
    skip "no qemu-system-x86_64 (Debian: qemu-system-x86)"
[ "$(uname -m)" = x86_64 ] || skip "the VM test boots Debian's amd64 kernel: x86_64 hosts only"
BUSYBOX=$(command -v busybox || true)
[ -n "$BUSYBOX" ] && ! ldd "$BUSYBOX" >/dev/null 2>&1 ||
    skip "no statically linked busybox (Debian: busybox-static)"
command -v python3 >/dev/null 2>&1 || skip "no python3 (builds the initramfs)"

# ---- kernel and modules (cached)
rc=0
sh "$HERE/vm_prepare.sh" "$CACHE" || rc=$?
[ $rc = 0 ] || exit $rc
T1=$(date +%s)

# ---- the reference: the same run through the sim port, on this host
mkdir -p "$WORK"
WORK=$(cd "$WORK" && pwd)
rm -rf "$WORK/root"
R=$WORK/root
mkdir -p "$R/bin" "$R/etc" "$R/dev" "$R/proc" "$R/sys" "$R/tmp" "$R/lib/modules" "$R/scenarios"
"$FW" --port sim --machine "$MACHINE" --scenario "$SCENARIO" --samples "$SAMPLES" \
      --params-out "$R/etc/ref-params.txt" >"$WORK/ref.json" ||
    { echo "vm_run: the sim-port reference run failed"; cat "$WORK/ref.json"; exit 1; }
echo "vm_run: reference (sim port, this host): $(cat "$WORK/ref.json")"

# ---- initramfs: busybox, our two programs with their shared libraries, modules, data
cp "$BUSYBOX" "$R/bin/busybox"
ln -s busybox "$R/bin/sh"
for b in "$FW" "$SIM" $CAN_CHECK; do
    cp "$b" "$R/bin/"
    # The build links libcjson and libgpiod dynamically (Debian ships no libcjson.a): the
    # libraries go in at the paths the dynamic loader looks for them.
    for lib in $(ldd "$b" | awk '$2 == "=>" && $3 ~ /^\// { print $3 } $1 ~ /^\// { print $1 }'); do
        mkdir -p "$R$(dirname "$lib")"
        cp -L "$lib" "$R$lib"
    done
done
cp "$CACHE"/modules/*.ko "$R/lib/modules/"
# The scenario names its model file relative to itself: copy its whole directory.
cp "$(dirname "$SCENARIO")"/*.json "$R/scenarios/"
VM_SCENARIO=/scenarios/$(basename "$SCENARIO")
# dhcal-fw in the test VM is configured by its machine file alone: the example's, with the
# acquisition of the sim-port reference run and a longer reply timeout (TCG emulates one CPU
# for both processes, on a host that may be busy with other tests: the drives get a second to
# be scheduled; a lost frame still ends the run at once).
python3 - "$MACHINE" "$R/etc/machine.json" "$SAMPLES" <<'PY'
import json, sys
machine = json.load(open(sys.argv[1]))
machine["can"] = dict(machine.get("can", {}), interface="vcan0", reply_timeout_us=1000000)
machine["acquisition"] = {"samples": int(sys.argv[3])}
json.dump(machine, open(sys.argv[2], "w"), indent=1)
PY
cat >"$R/etc/dhcal-vm.env" <<EOF
MACHINE=/etc/machine.json
SCENARIO=$VM_SCENARIO
FAULT_TICK=$FAULT_TICK
SAMPLES=$SAMPLES
EOF
cp "$HERE/vm_init.sh" "$R/init"
chmod +x "$R/init"
python3 "$HERE/mkcpio.py" "$R" "$WORK/initrd.cpio.gz"
T2=$(date +%s)

# ---- boot
# -cpu max: the emulated CPU offers FMA and AVX2 as this host's does, so glibc's libm picks
# the same code paths as for the host's reference run (a last-bit difference in sin() is
# enough to change a 100 000-tick servo trajectory).
ACCEL="-accel tcg -cpu max"
if [ "${DHCAL_VM_ACCEL:-tcg}" = kvm ] && [ -w /dev/kvm ]; then
    ACCEL="-enable-kvm -cpu host"
fi
echo "vm_run: booting $(cat "$CACHE/kernel-release") ($ACCEL), console in $WORK/console.log"
rc=0
timeout "$TIMEOUT" qemu-system-x86_64 $ACCEL -m 512 -smp 1 -nographic -no-reboot \
    -kernel "$CACHE/vmlinux" -initrd "$WORK/initrd.cpio.gz" \
    -append "console=ttyS0 quiet panic=-1" </dev/null >"$WORK/console.raw" 2>&1 || rc=$?
tr -d '\r' <"$WORK/console.raw" >"$WORK/console.log"
T3=$(date +%s)
grep -E '^(INFO|CASE|OUT|ERR|RESULT)' "$WORK/console.log" || true
echo "vm_run: prepare $((T1 - T0)) s, reference + initramfs $((T2 - T1)) s, VM $((T3 - T2)) s" \
     "(qemu exit $rc), total $((T3 - T0)) s"

# ---- verdict: every expected case reported, every one PASS
fail=0
cases="calibration lost-frame"
[ -n "$CAN_CHECK" ] && cases="can-transport $cases"
for c in $cases bus-timeout sigterm encoder-count missed-edge missing-interface \
         missing-chip missing-line probe-high probe-low probe-silent missing-probe-line; do
    line=$(grep "^CASE $c " "$WORK/console.log" | head -n1 || true)
    case $line in
        "CASE $c PASS"*) ;;
        "") echo "vm_run: case $c did not report"; fail=1 ;;
        *) fail=1 ;;
    esac
done
grep -q '^RESULT: ALL PASS' "$WORK/console.log" || fail=1
if [ $fail = 0 ]; then
    echo "vm_run: PASS"
    exit 0
fi
[ $rc = 124 ] && echo "vm_run: the VM did not finish within $TIMEOUT s"
tail -n 30 "$WORK/console.log"
echo "vm_run: FAIL"
exit 1
