#!/usr/bin/env python3
"""The controller's job measures a plan made at the desk (docs/cli.md, sections 3 and 4):
`dhcal-demo --plan P.csv` and `dhcal-fw --plan P.csv` hand the file's poses to the job
(fw_job_config.poses) instead of drawing their own.

- the plan: `dhcal plan --discriminate joint_compliance:2,joint_harmonic:2` on the scenario's
  model (12 poses, some at the ends of the joint ranges);
- dhcal-demo measures exactly those poses, in order: its samples.csv has one row per pose and
  every encoder angle within 2 counts of the plan's (the servo settles within 5e-5 rad, 1.6
  counts, and the sample keeps the hold's last reading); the count is the scenario's
  (encoder lines x 4 x the controller's gear ratio per turn);
- dhcal-fw --port sim measures as many samples and completes;
- bad plan files are refused before anything moves, exit 2, naming the file and the line:
  an angle outside its joint's range, NaN, more poses than the job holds, too few poses,
  and --plan together with --samples.
"""
import argparse
import json
import math
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FAILS = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILS.append(what)


def rows(path):
    lines = [l.strip() for l in open(path) if l.strip() and not l.startswith("#")]
    head = lines[0].split(",")
    return head, [dict(zip(head, (float(x) for x in l.split(",")))) for l in lines[1:]]


def count_deg(scenario, joint):
    """One encoder count at the joint, in degrees, as the controller converts it."""
    s = json.load(open(scenario))
    d = s.get("joint_defaults", {})
    j = s["joints"][joint]
    lines = j.get("encoder", {}).get("lines") or d["encoder"]["lines"]
    ratio = (j.get("controller", {}).get("gear_ratio") or j.get("gear", {}).get("ratio")
             or d["gear"]["ratio"])
    return 360.0 / (4.0 * lines * ratio)


def bad_plans(prog, base_args, scratch, label):
    header = "q1,q2,q3\n"
    ok_row = "10,60,-60\n"
    cases = {
        "range.csv": (header + ok_row * 2 + "10,175,-60\n" + ok_row * 8, ":4:",
                      "outside joint 2's range"),
        "nan.csv": (header + ok_row + "10,nan,-60\n" + ok_row * 9, ":3:", "'q2'"),
        "many.csv": (header + ok_row * 129, ":130:", "at most 128"),
        "few.csv": (header + ok_row * 5, "few.csv", "at least 10"),
    }
    for name, (text, where, what) in cases.items():
        path = os.path.join(scratch, label + "-" + name)
        open(path, "w").write(text)
        p = subprocess.run([prog] + base_args + ["--plan", path], capture_output=True,
                           text=True, timeout=120)
        first = p.stderr.strip().splitlines()[0] if p.stderr.strip() else ""
        check(p.returncode == 2 and os.path.basename(path) + (where if where.startswith(":")
                                                              else "") in p.stderr
              and what in p.stderr and "--plan" in p.stderr,
              "%s --plan %s: exit 2 naming the file and line (%d: %s)"
              % (label, name, p.returncode, first))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--demo", required=True)
    ap.add_argument("--dhcal", required=True)
    ap.add_argument("--fw")
    ap.add_argument("--scratch", required=True)
    a = ap.parse_args()
    os.makedirs(a.scratch, exist_ok=True)
    scen = os.path.join(ROOT, "host_sim", "scenarios", "joint_compliance_2.json")
    model = os.path.join(ROOT, "host_sim", "scenarios", "paper-3dof-model.json")
    plan = os.path.join(a.scratch, "plan.csv")
    p = subprocess.run([a.dhcal, "plan", "--model", model, "--poses", "12", "--discriminate",
                        "joint_compliance:2,joint_harmonic:2", "--out", plan],
                       capture_output=True, text=True)
    check(p.returncode == 0, "dhcal plan --discriminate writes the plan")
    out = os.path.join(a.scratch, "demo")
    os.makedirs(out, exist_ok=True)
    p = subprocess.run([a.demo, "--scenario", scen, "--plan", plan, "--out", out, "--json"],
                       capture_output=True, text=True, timeout=600)
    check(p.returncode == 0, "dhcal-demo --plan runs (exit %d%s)"
          % (p.returncode, "" if p.returncode == 0 else ": " + p.stderr[-300:]))
    res = json.loads(p.stdout) if p.returncode == 0 else {}
    _, planned = rows(plan)
    _, samples = rows(os.path.join(out, "samples.csv")) if p.returncode == 0 else (None, [])
    check(res.get("samples") == len(planned) == len(samples) == 12,
          "one sample per planned pose (%s, %d)" % (res.get("samples"), len(samples)))
    worst = 0.0
    for s, q in zip(samples, planned):
        for j in range(3):
            k = "q%d" % (j + 1)
            worst = max(worst, abs(s[k] - q[k]) / count_deg(scen, j))
    print("     largest |sample - plan|: %.2f encoder counts" % worst)
    check(len(samples) == 12 and worst <= 2.0,
          "every sample's encoder angles within 2 counts of its planned pose, in order "
          "(largest %.2f)" % worst)
    check("the given plan of 12 poses" in p.stderr, "the report names the given plan")
    bad_plans(a.demo, ["--scenario", scen], a.scratch, "dhcal-demo")
    p = subprocess.run([a.demo, "--scenario", scen, "--plan", plan, "--samples", "20"],
                       capture_output=True, text=True, timeout=60)
    check(p.returncode == 2 and "--plan" in p.stderr, "dhcal-demo: --plan with --samples is a "
                                                      "usage error")
    if a.fw:
        machine = os.path.join(ROOT, "examples", "machines", "paper-arm.json")
        base = ["--machine", machine, "--port", "sim", "--scenario", scen]
        p = subprocess.run([a.fw] + base + ["--plan", plan], capture_output=True, text=True,
                           timeout=600)
        r = json.loads(p.stdout) if p.returncode == 0 else {}
        check(p.returncode == 0 and r.get("samples") == 12 and r.get("fault") == "none",
              "dhcal-fw --port sim --plan measures the 12 poses (%d, %s)"
              % (p.returncode, r.get("samples")))
        bad_plans(a.fw, base, a.scratch, "dhcal-fw")
        p = subprocess.run([a.fw] + base + ["--plan", plan, "--samples", "20"],
                           capture_output=True, text=True, timeout=60)
        check(p.returncode == 2 and "--plan" in p.stderr, "dhcal-fw: --plan with --samples "
                                                          "is a usage error")
    if FAILS:
        print("%d check(s) failed" % len(FAILS))
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
