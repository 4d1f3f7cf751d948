#!/usr/bin/env python3
"""The judgement's threads change nothing but the time (docs/cli.md 1.5, DHCAL_THREADS).

`dhcal diagnose` and `dhcal refine --json` are run with the candidates judged one after
another (DHCAL_THREADS=1), on two threads, and on more threads than candidates; the reports
must be the same bytes. On the example data (examples/data/compliance) and, where the real
data are present, on the UR5 and the WAM (../shared/realdata, skipped with the reason when
absent), whose refine steps refit six candidates each.
"""
import argparse
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FAILS = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILS.append(what)


def report(dhcal, args, threads):
    env = dict(os.environ, DHCAL_THREADS=str(threads))
    p = subprocess.run([dhcal] + args, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit("%s exited %d with DHCAL_THREADS=%d:\n%s" % (" ".join(args), p.returncode,
                                                            threads, p.stderr))
    return p.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dhcal", required=True)
    ap.add_argument("--realdata", default=os.path.join(ROOT, "..", "shared", "realdata"))
    a = ap.parse_args()
    sets = [("example", os.path.join(ROOT, "examples", "data", "compliance", "model.json"),
             os.path.join(ROOT, "examples", "data", "compliance", "train.csv"), [])]
    for name in ("ur5-jacobi", "wam-jacobi"):
        d = os.path.join(a.realdata, name)
        if os.path.isdir(d):
            sets.append((name, os.path.join(d, "model.json"), os.path.join(d, "data.csv"),
                         ["--effects", "base_frame,tool_offset"]))
        else:
            print("skip %s: %s is absent (the shared real data)" % (name, d))
    for name, model, data, extra in sets:
        for cmd in (["diagnose"], ["refine", "--json"]):
            args = cmd + ["--model", model, "--data", data] + extra
            one = report(a.dhcal, args, 1)
            check(len(one) > 100, "%s %s: a report (%d bytes)" % (name, cmd[0], len(one)))
            for threads in (2, 8):
                check(report(a.dhcal, args, threads) == one,
                      "%s %s: %d threads give the bytes of one" % (name, cmd[0], threads))
    if FAILS:
        sys.exit("%d checks failed" % len(FAILS))


if __name__ == "__main__":
    main()
