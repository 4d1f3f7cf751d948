#!/bin/sh
# PID 1 of the linux-port test VM: real kernel devices (vcan0, a gpio-sim chip), the
# unmodified dhcal-fw against dhcal-sim over them. Prints one "CASE <name> PASS|FAIL <why>"
# line per case and "RESULT: ALL PASS" or "RESULT: SOME FAILED" on the console, which the
# host (vm_run.sh) parses; then powers off. /etc/dhcal-vm.env holds the host's settings.
/bin/busybox --install -s /bin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
mount -t tmpfs tmpfs /tmp
. /etc/dhcal-vm.env
echo "INFO kernel $(uname -r), up $(cut -d' ' -f1 /proc/uptime) s"
FAILED=0
result() { # name PASS|FAIL detail
    echo "CASE $1 $2 $3"
    [ "$2" = PASS ] || FAILED=1
}
show() { # prefix file: the outputs into the console log, for the host and for people
    [ -s "$2" ] && sed "s/^/$1 /" "$2"
}
settle() { # let a background dhcal-sim open its socket
    usleep 300000
}
field() { # file key: the first value of key in a one-line JSON object
    awk -v k="$2" 'NR == 1 { if (!match($0, "\"" k "\": *")) exit;
        s = substr($0, RSTART + RLENGTH); sub(/^"/, "", s); sub(/["},].*/, "", s); print s }' "$1"
}

# ---------------------------------------------------------------- devices
M=/lib/modules
# Debian's .deb has no modules.dep (depmod runs at install): dependency order by hand.
for m in can can-raw can-dev vcan configfs irq_sim_oot gpio-sim-oot; do
    insmod $M/$m.ko || echo "INFO insmod $m failed"
done
ip link add dev vcan0 type vcan && ip link set up vcan0 ||
    result setup-vcan0 FAIL "cannot create vcan0"
mount -t configfs configfs /sys/kernel/config
G=/sys/kernel/config/gpio-sim/enc
CHIP=
if mkdir $G $G/bank0 2>/dev/null; then
    echo 4 >$G/bank0/num_lines
    echo 1 >$G/live && CHIP=$(cat $G/bank0/chip_name)
fi
[ -n "$CHIP" ] || result setup-gpio-sim FAIL "cannot create a gpio-sim chip"
echo "INFO vcan0 up, gpio-sim chip '$CHIP', up $(cut -d' ' -f1 /proc/uptime) s"
cd /tmp

# ---------------------------------------------------------------- the transport alone
if [ -x /bin/linux_can_check ]; then
    linux_can_check vcan0 >can-check.txt 2>&1
    RC=$?
    show "OUT can-check" can-check.txt
    if [ $RC = 0 ]; then result can-transport PASS "kernel ID filter, exact frames, timeouts kept under EINTR, drops reported (SO_RXQ_OVFL)"
    else result can-transport FAIL "exit $RC"; fi
fi

# ---------------------------------------------------------------- (a) the calibration run
t0=$(cut -d' ' -f1 /proc/uptime)
dhcal-sim bus --scenario "$SCENARIO" --can vcan0 >sim-a.json 2>sim-a.err &
SIM=$!
settle # (dhcal-fw repeats its first SYNC until the drives answer; this saves a timeout)
dhcal-fw --machine "$MACHINE" --nv nv-a.bin --params-out params-a.txt \
    >fw-a.json 2>fw-a.err
RC=$?
wait $SIM
t1=$(cut -d' ' -f1 /proc/uptime)
show "OUT fw-a" fw-a.json; show "ERR fw-a" fw-a.err; show "OUT sim-a" sim-a.json
show "ERR sim-a" sim-a.err
# The reference: the same run through the sim port, in this VM (same CPU, same libm).
dhcal-fw --port sim --machine "$MACHINE" --scenario "$SCENARIO" --samples "$SAMPLES" \
    --params-out params-s.txt >fw-s.json 2>fw-s.err
show "OUT fw-s" fw-s.json; show "ERR fw-s" fw-s.err
# Same parameter names in the same order; prints "ok|names COUNT MAX|difference|".
compare() {
    awk 'NR == FNR { ref[FNR] = $1; val[FNR] = $2; n = FNR; next }
         { if ($1 != ref[FNR]) bad = 1; d = $2 - val[FNR]; if (d < 0) d = -d;
           if (d > max) max = d; m = FNR }
         END { if (m != n || n == 0) bad = 1;
               printf "%s %d %.3g", (bad ? "names" : "ok"), n, max + 0 }' "$1" "$2" 2>/dev/null
}
CMP=$(compare params-s.txt params-a.txt)
HOST=$(compare /etc/ref-params.txt params-a.txt)
echo "INFO linux port in the VM against the sim port on the build host: $HOST"
set -- $CMP
if [ "$RC" = 0 ] && [ "$1" = ok ] && awk "BEGIN { exit !($3 <= 1e-9) }"; then
    result calibration PASS "$2 parameters, max |linux - sim port| = $3 (against the build host's sim run: $(echo $HOST | cut -d' ' -f3)), effect $(field fw-a.json effect), wire RMS $(field fw-a.json wire_rms_mm) mm, $(field fw-a.json ticks) ticks in $(awk "BEGIN { print $t1 - $t0 }") s"
else
    result calibration FAIL "exit $RC, against the sim port: '$CMP', against the build host's: '$HOST' (ok|names, count, max diff)"
fi

# ---------------------------------------------------------------- (b), (c) bus faults
# The controller must latch port_timeout and command 0 V (code 2048) to every drive; the
# simulated drives report the last command they received. They stay on the bus 3 s after
# its last frame: the controller declares the lost frame only after its reply timeout (1 s
# in this VM), and a drive that left at the same moment would miss the 0 V.
fault_case() { # name "dhcal-fw options" dhcal-sim-options...
    name=$1; fw_opts=$2; shift 2
    dhcal-sim bus --scenario "$SCENARIO" --can vcan0 --idle-exit-ms 3000 "$@" \
        >sim-$name.json 2>sim-$name.err &
    SIM=$!
    settle
    # shellcheck disable=SC2086 # word splitting intended: an option list
    dhcal-fw --machine "$MACHINE" --nv nv-$name.bin $fw_opts >fw-$name.json \
        2>fw-$name.err
    RC=$?
    wait $SIM
    show "OUT fw-$name" fw-$name.json; show "OUT sim-$name" sim-$name.json
    F=$(field fw-$name.json fault)
    DAC=$(sed -n 's/.*"last_dac": *\[\([^]]*\)\].*/\1/p' sim-$name.json | tr -d ' ')
    if [ "$RC" = 1 ] && [ "$F" = port_timeout ] && [ "$DAC" = "2048,2048,2048" ]; then
        result "$name" PASS "fault $F after $(field fw-$name.json ticks) ticks, drives commanded to 0 V (codes $DAC)"
    else
        result "$name" FAIL "exit $RC, fault '$F', last drive codes '$DAC'"
    fi
}
# The lost frame travels with the protocol moved by an identifier offset on both ends (the
# kernel filters included): the ticks before the fault show the moved bus works.
fault_case lost-frame "--can-id-offset 32" --can-id-offset 32 --drop-frame 0x181@$FAULT_TICK
fault_case bus-timeout "" --stop-at $FAULT_TICK

# ---------------------------------------------------------------- (c') a stop request
# SIGTERM in the middle of the run: the controller must command 0 V to every drive and
# disable it (Enable 0), report fault "stopped" and exit 1; the simulated drives report the
# last command and enable bit they received.
dhcal-sim bus --scenario "$SCENARIO" --can vcan0 --idle-exit-ms 3000 >sim-stop.json \
    2>sim-stop.err &
SIM=$!
settle
dhcal-fw --machine "$MACHINE" --nv nv-stop.bin >fw-stop.json 2>fw-stop.err &
FW=$!
sleep 3
kill -TERM $FW
wait $FW
RC=$?
wait $SIM
show "OUT fw-stop" fw-stop.json; show "ERR fw-stop" fw-stop.err; show "OUT sim-stop" sim-stop.json
F=$(field fw-stop.json fault)
DAC=$(sed -n 's/.*"last_dac": *\[\([^]]*\)\].*/\1/p' sim-stop.json | tr -d ' ')
EN=$(sed -n 's/.*"last_enable": *\[\([^]]*\)\].*/\1/p' sim-stop.json | tr -d ' ')
if [ "$RC" = 1 ] && [ "$F" = stopped ] && [ "$DAC" = "2048,2048,2048" ] && [ "$EN" = "0,0,0" ]; then
    result sigterm PASS "fault $F after $(field fw-stop.json ticks) ticks, drives commanded to 0 V (codes $DAC) and disabled (enable $EN)"
else
    result sigterm FAIL "exit $RC, fault '$F', last drive codes '$DAC', enable '$EN'"
fi

# ---------------------------------------------------------------- (d) encoder on GPIO
if [ -n "$CHIP" ]; then
    # Clean motion first: every edge seen, the count exact.
    dhcal-sim bus --gpio-chip "$CHIP" --lines 0,1 --gpio-steps 24 >sim-q.json 2>sim-q.err &
    SIM=$!
    dhcal-fw --gpio-chip "$CHIP" --enc-lines 0,1 --gpio-watch 24 >fw-q.json 2>fw-q.err
    RC=$?
    wait $SIM
    show "OUT fw-q" fw-q.json; show "ERR fw-q" fw-q.err; show "ERR sim-q" sim-q.err
    if [ "$RC" = 0 ] && [ "$(field fw-q.json counts)" = 24 ]; then
        result encoder-count PASS "24 quadrature steps on gpio-sim lines 0,1 counted exactly"
    else
        result encoder-count FAIL "exit $RC, counts '$(field fw-q.json counts)'"
    fi
    # The controller stalls while 34 steps go by: each line's 16-event kernel buffer
    # overflows, the 17th edge of each line is lost, the next edge repeats its predecessor.
    # Times: the burst at about 1.5-2 s, the stall until about 4 s, the next edges at about
    # 7 s (seconds of margin each way on a busy emulated CPU).
    dhcal-sim bus --gpio-chip "$CHIP" --lines 0,1 --gpio-steps 40 --gpio-burst 34 \
        --gpio-pause-ms 5000 --gpio-step-us 0 >sim-m.json 2>sim-m.err &
    SIM=$!
    dhcal-fw --gpio-chip "$CHIP" --enc-lines 0,1 --gpio-watch 40 --gpio-stall-ms 4000 \
        --gpio-timeout-ms 10000 >fw-m.json 2>fw-m.err
    RC=$?
    wait $SIM
    show "OUT fw-m" fw-m.json; show "ERR sim-m" sim-m.err
    F=$(field fw-m.json fault)
    if [ "$RC" = 1 ] && [ "$F" = encoder_jump ]; then
        result missed-edge PASS "fault $F: $(field fw-m.json detail) after $(field fw-m.json edges) edges"
    else
        result missed-edge FAIL "exit $RC, fault '$F', $(field fw-m.json detail)"
    fi
fi

# ---------------------------------------------------------------- (e) touch probe on GPIO
if [ -n "$CHIP" ]; then
    # The probe's switch on line 2, closed 5 times by gpio-sim's pull (what the probe's
    # output does to the input), once with the active level high and once low.
    PULL=/sys/bus/gpio/devices/$CHIP/sim_gpio2/pull
    for active in high low; do
        [ $active = high ] && { OPEN=pull-down; CLOSE=pull-up; } || { OPEN=pull-up; CLOSE=pull-down; }
        echo $OPEN >$PULL
        dhcal-fw --gpio-chip "$CHIP" --probe-line 2 --probe-active $active --probe-watch 5 \
            --gpio-timeout-ms 10000 >fw-p-$active.json 2>fw-p-$active.err &
        FW=$!
        i=0
        while ! grep -q watching fw-p-$active.err 2>/dev/null && [ $i -lt 100 ]; do
            usleep 100000; i=$((i + 1))
        done
        for k in 1 2 3 4 5; do
            echo $CLOSE >$PULL; usleep 200000
            echo $OPEN >$PULL; usleep 200000
        done
        wait $FW
        RC=$?
        show "OUT fw-p-$active" fw-p-$active.json; show "ERR fw-p-$active" fw-p-$active.err
        if [ "$RC" = 0 ] && [ "$(field fw-p-$active.json closings)" = 5 ] &&
            [ "$(field fw-p-$active.json closed_at_start)" = false ]; then
            result probe-$active PASS "5 closings of the probe's switch on gpio-sim line 2, active $active"
        else
            result probe-$active FAIL "exit $RC, closings '$(field fw-p-$active.json closings)', $(field fw-p-$active.json detail)"
        fi
    done
    echo pull-down >$PULL
    # Nothing touched: the watch ends with the fault and the time it waited.
    dhcal-fw --gpio-chip "$CHIP" --probe-line 2 --probe-watch 1 --gpio-timeout-ms 500 \
        >fw-p-none.json 2>fw-p-none.err
    RC=$?
    if [ "$RC" = 1 ] && [ "$(field fw-p-none.json fault)" = probe ]; then
        result probe-silent PASS "no closing: fault probe, $(field fw-p-none.json detail)"
    else
        result probe-silent FAIL "exit $RC, fault '$(field fw-p-none.json fault)'"
    fi
fi

# ---------------------------------------------------------------- configuration errors
err_case() { # name expected-text dhcal-fw-options...
    name=$1; want=$2; shift 2
    dhcal-fw --machine "$MACHINE" "$@" >/dev/null 2>err-$name.txt
    RC=$?
    if [ "$RC" = 2 ] && grep -q "$want" err-$name.txt; then
        result "$name" PASS "exit 2: $(head -n1 err-$name.txt)"
    else
        result "$name" FAIL "exit $RC: $(head -n1 err-$name.txt)"
    fi
}
err_case missing-interface "no CAN interface" --can nosuch0
err_case missing-chip "no GPIO chip" --gpio-chip gpiochip99 --enc-lines 0,1
[ -n "$CHIP" ] && err_case missing-line "no line 9" --gpio-chip "$CHIP" --enc-lines 0,9
[ -n "$CHIP" ] && err_case missing-probe-line "no line 9 (probe)" --gpio-chip "$CHIP" \
    --probe-line 9 --probe-watch 1

dmesg | grep -iE "gpio|can:|vcan|kfifo|drop" | sed 's/^/DMESG /'
if [ $FAILED = 0 ]; then echo "RESULT: ALL PASS"; else echo "RESULT: SOME FAILED"; fi
echo "INFO up $(cut -d' ' -f1 /proc/uptime) s at the end"
poweroff -f
