#!/usr/bin/env python3
"""dhcal plan --discriminate A,B (docs/cli.md, 1.7): poses that tell two look-alike effects apart.

1. Planned against random poses, with the test's own kinematics: the model files' forward
   kinematics (docs/formats.md 2.2: Rz(q + theta) Rx(alpha) Ry(beta), a along the rotated x,
   d along z; Hayati's beta on a joint whose axis is parallel to the next), the measurer's
   wire lengths, and the two effects' columns (joint_scale:i: dq = s q; joint_harmonic:i:
   dq = A sin q + B cos q) by central differences. The correlation of the two signatures is
   the cosine of the smallest angle between the spans of A's and B's columns once the
   geometry's columns (theta, d or beta, a, alpha of every joint) are projected out: the
   largest correlation diagnose can find between their fitted tool-error fields when one
   of them is the truth. On the paper's 3-DOF arm (wire lengths) and on a 6-DOF arm (tool
   points), the plan's poses must be less correlated than every one of 20 draws of as many
   random poses, and dhcal's own number for the plan must agree with the test's.
2. The paper's arm in examples/data/compliance (joint_compliance:2 hidden): the correlation
   `plan --data` computes over the data must be diagnose's look-alike correlation, and the
   plan's poses must lower it below that of as many random poses.
3. End to end: a simulated arm with a joint_scale:2 error (host_sim scenario, joint 2's gear
   ratio 100.3 where the controller assumes 100) measured at random poses whose q2 spans
   80 deg only: diagnose reports joint_harmonic:2 as a look-alike of its choice. With the
   planned poses measured too (dhcal-sim dataset --plan), it names joint_scale:2 and no
   longer reports joint_harmonic:2 as its look-alike.
4. Bad input: exit 2 naming the option, the output untouched.
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FAILS = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILS.append(what)


def run(args, expect=0):
    p = subprocess.run(args, capture_output=True, text=True)
    if expect is not None and p.returncode != expect:
        sys.exit("command %s exited %d (expected %d):\n%s%s"
                 % (" ".join(args), p.returncode, expect, p.stdout, p.stderr))
    return p


# ---------------------------------------------------------------- the test's kinematics

def rot(axis, t):
    c, s = math.cos(t), math.sin(t)
    if axis == "x":
        return [[1, 0, 0], [0, c, -s], [0, s, c]]
    if axis == "y":
        return [[c, 0, s], [0, 1, 0], [-s, 0, c]]
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]]


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def apply(r, v):
    return [sum(r[i][k] * v[k] for k in range(3)) for i in range(3)]


def rpy(deg):
    r, p, y = (math.radians(x) for x in deg)
    return mul(rot("z", y), mul(rot("y", p), rot("x", r)))


class Arm:
    """A model file (docs/formats.md, section 2) as the test reads it."""

    def __init__(self, path):
        m = json.load(open(path))
        self.joints = []
        for j in m["joints"]:
            self.joints.append({"theta": math.radians(j.get("theta_offset_deg", 0.0)),
                                "d": j["d_mm"], "a": j["a_mm"],
                                "alpha": math.radians(j["alpha_deg"]),
                                "beta": math.radians(j.get("beta_deg", 0.0)),
                                "min": j.get("min_deg", -180.0), "max": j.get("max_deg", 180.0)})
        n = len(self.joints)
        # Hayati's beta replaces d on a joint whose axis is parallel to the next
        self.hayati = [abs(math.sin(j["alpha"])) < 1e-3 and i + 1 < n
                       for i, j in enumerate(self.joints)]
        self.tool = m.get("tool_mm", [0, 0, 0])
        base = m.get("base", {})
        self.base_r = rpy(base.get("rpy_deg", [0, 0, 0]))
        self.base_t = base.get("xyz_mm", [0, 0, 0])
        self.anchors = None
        if "measurer" in m:
            fr = m["measurer"].get("frame", {})
            r = rpy(fr.get("rpy_deg", [0, 0, 0]))
            t = fr.get("xyz_mm", [0, 0, 0])
            self.anchors = [[x + y for x, y in zip(apply(r, a), t)]
                            for a in m["measurer"]["anchors_mm"]]

    def params(self):
        """The geometry's parameters: (joint, name) in each joint's convention."""
        return [(i, k) for i in range(len(self.joints))
                for k in ("theta", "beta" if self.hayati[i] else "d", "a", "alpha")]

    def tool_point(self, q, joints):
        r = self.base_r
        p = list(self.base_t)
        for qi, j in zip(q, joints):
            phi = qi + j["theta"]
            off = [j["a"] * math.cos(phi), j["a"] * math.sin(phi), j["d"]]
            p = [x + y for x, y in zip(p, apply(r, off))]
            r = mul(r, mul(rot("z", phi), mul(rot("x", j["alpha"]), rot("y", j["beta"]))))
        return [x + y for x, y in zip(p, apply(r, self.tool))]

    def measure(self, q, joints=None):
        """What is measured: the wire lengths when the model has a measurer, else x,y,z."""
        p = self.tool_point(q, joints or self.joints)
        if self.anchors is None:
            return p
        return [math.dist(p, a) for a in self.anchors]

    def columns(self, q, effects):
        """Per parameter, d(measured)/d(parameter) at q: the geometry's, then each effect's."""
        cols = []
        for i, k in self.params():
            h = 1e-6 if k in ("theta", "beta", "alpha") else 1e-4
            jp = [dict(j) for j in self.joints]
            jm = [dict(j) for j in self.joints]
            jp[i][k] += h
            jm[i][k] -= h
            cols.append([(u - v) / (2 * h) for u, v in zip(self.measure(q, jp),
                                                           self.measure(q, jm))])
        for kind, i in effects:
            h = 1e-6
            qp, qm = list(q), list(q)
            qp[i] += h
            qm[i] -= h
            dq = [(u - v) / (2 * h) for u, v in zip(self.measure(qp), self.measure(qm))]
            shapes = {"scale": [q[i]], "harmonic": [math.sin(q[i]), math.cos(q[i])]}[kind]
            cols += [[s * x for x in dq] for s in shapes]
        return cols


def orthonormal(vectors):
    basis = []
    for v in vectors:
        w = list(v)
        for _ in range(2):
            for b in basis:
                d = sum(x * y for x, y in zip(w, b))
                w = [x - d * y for x, y in zip(w, b)]
        n = math.sqrt(sum(x * x for x in w))
        if n > 1e-7 * max(1.0, math.sqrt(sum(x * x for x in v))):
            basis.append([x / n for x in w])
    return basis


def correlation(arm, poses_deg, a, b):
    """Cosine of the smallest angle between span(M_G A) and span(M_G B) over the poses
    (a: one column, b: any number)."""
    ng = len(arm.params())
    stacked = None
    for q in poses_deg:
        cols = arm.columns([math.radians(x) for x in q], [a, b])
        if stacked is None:
            stacked = [[] for _ in cols]
        for s, c in zip(stacked, cols):
            s.extend(c)
    g = orthonormal(stacked[:ng])

    def project_out(v):
        w = list(v)
        for _ in range(2):
            for u in g:
                d = sum(x * y for x, y in zip(w, u))
                w = [x - d * y for x, y in zip(w, u)]
        return w
    va = project_out(stacked[ng])
    vb = orthonormal([project_out(c) for c in stacked[ng + 1:]])
    na = math.sqrt(sum(x * x for x in va))
    along = math.sqrt(sum(sum(x * y for x, y in zip(va, u)) ** 2 for u in vb))
    return along / na


def random_poses(arm, n, rng):
    return [[rng.uniform(j["min"], j["max"]) for j in arm.joints] for _ in range(n)]


def read_plan(path):
    rows = [l for l in open(path) if l.strip() and not l.startswith("#")]
    return [[float(x) for x in l.split(",")] for l in rows[1:]]


# ---------------------------------------------------------------- 1. planned against random

def planned_against_random(dhcal, scratch, model, pair, n, label):
    arm = Arm(model)
    out = os.path.join(scratch, label + "-plan.csv")
    p = run([dhcal, "plan", "--model", model, "--poses", str(n), "--discriminate",
             "%s:%d,%s:%d" % (pair[0][0].replace("scale", "joint_scale"), pair[0][1] + 1,
                              pair[1][0].replace("harmonic", "joint_harmonic"), pair[1][1] + 1),
             "--out", out, "--json"])
    rep = json.loads(p.stdout)["discriminate"]
    plan = read_plan(out)
    check(len(plan) == n, "%s: the plan has %d poses" % (label, n))
    mine = correlation(arm, plan, pair[0], pair[1])
    rng = random.Random(11)
    rand = sorted(correlation(arm, random_poses(arm, n, rng), pair[0], pair[1])
                  for _ in range(20))
    print("     %s: planned %.4f (dhcal: %.4f), random %d poses: median %.4f, least of 20 "
          "%.4f (dhcal's random plan %.4f)" % (label, mine, rep["correlation_after_a"], n,
                                               rand[10], rand[0], rep["correlation_random"]))
    check(mine < rand[0], "%s: the planned poses (%.4f) are less correlated than each of 20 "
                          "random draws (least %.4f)" % (label, mine, rand[0]))
    check(abs(mine - rep["correlation_after_a"]) < 0.02,
          "%s: dhcal's correlation of the plan, with the scale the truth (%.4f), is the "
          "test's (%.4f)" % (label, rep["correlation_after_a"], mine))
    check(rep["correlation_after"] < rep["correlation_random"],
          "%s: dhcal reports the plan below its random plan (%.4f < %.4f)"
          % (label, rep["correlation_after"], rep["correlation_random"]))
    return mine, rand[10]


# ---------------------------------------------------------------- 2. the paper's data

def look_alike_r(diag, a, b):
    for c in diag["candidates"]:
        lab = c["effect"] + (":%d" % c["joint"] if c.get("joint") else "")
        if lab == a:
            for d in c.get("look_alike_detail", []):
                if d["effect"] == b:
                    return d["correlation"]
    return None


def label_of(c):
    return c["effect"] + (":%d" % c["joint"] if c.get("joint") else "")


def compliance_data(dhcal, scratch):
    d = os.path.join(ROOT, "examples", "data", "compliance")
    model, train = os.path.join(d, "model.json"), os.path.join(d, "train.csv")
    diag = json.loads(run([dhcal, "diagnose", "--model", model, "--data", train,
                           "--json"]).stdout)
    r = look_alike_r(diag, "joint_compliance:2", "joint_harmonic:2")
    check(r is not None and r > 0.9, "examples/data/compliance: diagnose reports "
          "joint_harmonic:2 as a look-alike of joint_compliance:2 (%s)" % r)
    out = os.path.join(scratch, "compliance-plan.csv")
    rep = json.loads(run([dhcal, "plan", "--model", model, "--data", train, "--poses", "10",
                          "--discriminate", "joint_compliance:2,joint_harmonic:2",
                          "--out", out, "--json"]).stdout)
    dd = rep["discriminate"]
    print("     compliance: diagnose %.4f; plan --data: data %.4f, with 10 random %.4f, with "
          "the plan %.4f" % (r or 0.0, dd["correlation_data"], dd["correlation_random"],
                             dd["correlation_after"]))
    check(r is not None and abs(dd["correlation_data"] - r) < 0.01,
          "plan --data's correlation over the data (%.4f) is diagnose's (%s)"
          % (dd["correlation_data"], r))
    check(rep["data_rows"] == 60 and len(read_plan(out)) == 10, "60 data rows, 10 new poses")
    check(dd["correlation_after"] < dd["correlation_before"] and
          dd["correlation_after"] < dd["correlation_random"],
          "the plan lowers the correlation below the data's and 10 random poses' (%.4f < %.4f, "
          "%.4f)" % (dd["correlation_after"], dd["correlation_before"],
                     dd["correlation_random"]))


# ---------------------------------------------------------------- 3. end to end

def end_to_end(dhcal, sim, scratch):
    sc = os.path.join(ROOT, "host_sim", "scenarios")
    model = json.load(open(os.path.join(sc, "paper-3dof-model.json")))
    model["joints"][1]["min_deg"], model["joints"][1]["max_deg"] = -170, 170
    json.dump(model, open(os.path.join(scratch, "wide-model.json"), "w"), indent=1)
    s = json.load(open(os.path.join(sc, "joint_scale_1.json")))
    s["name"], s["model"] = "joint_scale_2_wide", "wide-model.json"
    s["comment"] = ("joint_scale:2 hidden: joint 2's gear ratio is 100.3, the controller "
                    "converts with 100; joint 2 turns +-170 deg")
    for k in ("gear", "controller"):
        s["joints"][0].pop(k, None)
    s["joints"][1]["gear"] = {"ratio": 100.3}
    s["joints"][1]["controller"] = {"gear_ratio": 100}
    scen = os.path.join(scratch, "joint_scale_2_wide.json")
    json.dump(s, open(scen, "w"), indent=1)
    rng = random.Random(5)
    narrow = os.path.join(scratch, "narrow-poses.csv")
    with open(narrow, "w") as f:
        f.write("q1,q2,q3\n")
        for _ in range(20):
            f.write("%.6f,%.6f,%.6f\n" % (rng.uniform(-170, 170), rng.uniform(40, 120),
                                          rng.uniform(-150, 150)))
    data = os.path.join(scratch, "narrow.csv")
    m = os.path.join(scratch, "e2e-model.json")
    run([sim, "dataset", "--scenario", scen, "--plan", narrow, "--out", data,
         "--model-out", m])
    before = json.loads(run([dhcal, "diagnose", "--model", m, "--data", data,
                             "--json"]).stdout)
    named = before.get("named")
    r0 = look_alike_r(before, named or "", "joint_harmonic:2" if named == "joint_scale:2"
                      else "joint_scale:2")
    print("     narrow data: named %s, look-alike correlation %s" % (named, r0))
    check(named in ("joint_scale:2", "joint_harmonic:2") and r0 is not None and r0 > 0.9,
          "over q2 in [40, 120] deg diagnose cannot tell joint_scale:2 from joint_harmonic:2")
    plan = os.path.join(scratch, "e2e-plan.csv")
    rep = json.loads(run([dhcal, "plan", "--model", m, "--data", data, "--poses", "20",
                          "--discriminate", "joint_scale:2,joint_harmonic:2", "--out", plan,
                          "--json"]).stdout)["discriminate"]
    print("     plan: data %.4f (diagnose's %.4f), after %.4f, 20 random %.4f"
          % (rep["correlation_before"], rep["correlation_data"], rep["correlation_after"],
             rep["correlation_random"]))
    check(r0 is not None and abs(rep["correlation_data"] - r0) < 0.01,
          "plan --data's correlation over the data is diagnose's")
    check(rep["correlation_after"] < 0.9, "the plan's predicted correlation is below 0.9")
    more = os.path.join(scratch, "planned.csv")
    run([sim, "dataset", "--scenario", scen, "--plan", plan, "--out", more, "--seed", "9"])
    union = os.path.join(scratch, "union.csv")
    with open(union, "w") as f:
        f.write(open(data).read())
        f.writelines([l for l in open(more) if not l.startswith("#")][1:])  # no header
    after = json.loads(run([dhcal, "diagnose", "--model", m, "--data", union,
                            "--json"]).stdout)
    lab = [c for c in after["candidates"] if label_of(c) == "joint_scale:2"]
    alikes = lab[0].get("look_alikes", []) if lab else None
    print("     with the plan's poses: named %s, its look-alikes %s, outliers %d"
          % (after.get("named"), alikes, len(after["outliers"])))
    check(after.get("named") == "joint_scale:2" and alikes is not None and
          "joint_harmonic:2" not in alikes,
          "with the plan's poses measured, diagnose names joint_scale:2 and no longer calls "
          "joint_harmonic:2 its look-alike")


# ---------------------------------------------------------------- 4. bad input

def bad_input(dhcal, scratch):
    m3 = os.path.join(ROOT, "examples", "models", "paper-3dof.json")
    m6 = os.path.join(ROOT, "examples", "models", "paper-6dof-nominal.json")
    out = os.path.join(scratch, "untouched.csv")
    open(out, "w").write("keep\n")
    cases = [
        (m3, ["--discriminate", "joint_scale:2"], "--discriminate"),
        (m3, ["--discriminate", "joint_scale:2,joint_scale:2"], "same effect"),
        (m3, ["--discriminate", "joint_scale:9,joint_harmonic:2"], "not an effect"),
        (m3, ["--discriminate", "joint_scale:2,bogus"], "not an effect"),
        (m3, ["--discriminate", "joint_scale:2,joint_harmonic:2", "--effects",
              "joint_scale:2"], "fitted already"),
        (m6, ["--discriminate", "measurer_scale,joint_scale:2"], "measurer"),
        (m3, ["--discriminate", "thermal_scale,joint_scale:2"], "temperature"),
        (m3, ["--discriminate", "joint_backlash:2,joint_scale:2"], "approach direction"),
        (m3, ["--data", os.path.join(ROOT, "examples", "data", "compliance", "train.csv")],
         "--data"),
        (m3, ["--discriminate", "joint_scale:2,joint_harmonic:2", "--data",
              os.path.join(scratch, "missing.csv")], "missing.csv"),
    ]
    for model, extra, word in cases:
        p = run([dhcal, "plan", "--model", model, "--poses", "5", "--out", out] + extra, None)
        named = "--data" in extra[0] or "missing" in word or "--discriminate" in p.stderr
        check(p.returncode == 2 and word in p.stderr and named,
              "plan %s: exit 2 naming '%s' (%d: %s)" % (" ".join(extra), word, p.returncode,
                                                       p.stderr.strip().splitlines()[0]
                                                       if p.stderr.strip() else ""))
    check(open(out).read() == "keep\n", "the output is untouched after bad input")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dhcal", required=True)
    ap.add_argument("--sim", required=True)
    ap.add_argument("--scratch", required=True)
    a = ap.parse_args()
    os.makedirs(a.scratch, exist_ok=True)
    m3 = os.path.join(ROOT, "examples", "models", "paper-3dof.json")
    m6 = os.path.join(ROOT, "examples", "models", "paper-6dof-nominal.json")
    planned_against_random(a.dhcal, a.scratch, m3, (("scale", 1), ("harmonic", 1)), 10,
                           "3-DOF joint_scale:2,joint_harmonic:2")
    planned_against_random(a.dhcal, a.scratch, m6, (("scale", 2), ("harmonic", 2)), 25,
                           "6-DOF joint_scale:3,joint_harmonic:3")
    compliance_data(a.dhcal, a.scratch)
    end_to_end(a.dhcal, a.sim, a.scratch)
    bad_input(a.dhcal, a.scratch)
    if FAILS:
        print("%d check(s) failed" % len(FAILS))
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
