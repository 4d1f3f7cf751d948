#!/usr/bin/env python3
"""profile.py - where a twin program's measured part spends its instructions on the
Cortex-M4: runs it under QEMU (-icount shift=0) in profile mode (twin_target.c), maps the
sampled program counters to functions with arm-none-eabi-nm and prints the flat profile.

  profile.py [--emulator QEMU_SH] [--top N] ELF ARGS...
e.g. (after ctest --preset cortex-m4 -R parity has written the sample files):
  tests/target/twin/profile.py build/cortex-m4/tests/target/twin/parity_fit \\
      $PWD/build/cortex-m4/tests/target/twin/scratch/fit_demo3.bin"""
import argparse
import bisect
import collections
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def functions(elf):
    out = subprocess.run(["arm-none-eabi-nm", "-S", "--defined-only", elf], check=True,
                         capture_output=True, text=True).stdout
    syms = []
    for line in out.splitlines():
        p = line.split()
        if len(p) == 4 and p[2] in "tTW":
            syms.append((int(p[0], 16) & ~1, int(p[1], 16), p[3]))
    syms.sort()
    return syms


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--emulator", default=os.path.join(HERE, "../../../cmake/qemu-mps2-an386.sh"))
    ap.add_argument("--top", type=int, default=20)
    ap.add_argument("elf")
    ap.add_argument("args", nargs="*")
    a = ap.parse_args()
    env = dict(os.environ, DHCAL_QEMU_OPTS="-icount shift=0")
    # semihosting output arrives on QEMU's stderr
    p = subprocess.run([a.emulator, a.elf, "profile"] + a.args, env=env, text=True,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, check=False)
    pcs = [int(l[3:], 16) for l in p.stdout.splitlines() if l.startswith("pc ")]
    if p.returncode != 0 or not pcs:
        print("\n".join(l for l in p.stdout.splitlines() if not l.startswith("pc ")))
        print(f"profile.py: exit {p.returncode}, {len(pcs)} samples", file=sys.stderr)
        return 1
    syms = functions(a.elf)
    starts = [s[0] for s in syms]
    count = collections.Counter()
    for pc in pcs:
        i = bisect.bisect_right(starts, pc & ~1) - 1
        ok = i >= 0 and pc < syms[i][0] + syms[i][1]
        count[syms[i][2] if ok else "?"] += 1
    n = len(pcs)
    print(f"{n} samples, one per 40 000 instructions")
    for name, c in count.most_common(a.top):
        print(f"  {100.0 * c / n:5.1f} %  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
