#!/usr/bin/env python3
"""Acceptance: one hidden effect per data set; `dhcal diagnose` must name it, `dhcal fit`
with it must reach the noise floor on held-out poses.

  run_acceptance.py --dhcal PATH [--work DIR] [--seed S] [--cases LIST] [--timeout SEC]
                    [--wrapper CMD]   (e.g. "qemu-aarch64 -L /usr/aarch64-linux-gnu")

For every case of hidden_effects.py (seed S*100 + k for the k-th case, 1-based):
  1. generate model.json, train.csv (60 poses), heldout.csv (40 poses), truth.json;
  2. dhcal diagnose --model model.json --data train.csv --json
     exit 0; the first of `candidates` has the hidden effect and joint and is significant;
     clean data: no candidate significant;
  3. dhcal fit --model model.json --data train.csv --heldout heldout.csv --effects NAME --json
     exit 0; heldout_rms_mm <= 1.25 x sqrt(3) x 0.05 mm (the noise floor); clean data: the
     fit without effects must meet that bound;
  4. dhcal fit ... without --effects (informational: the "error falls" figure).
Each case's directory under --work keeps the data and every command's stdout/stderr.
Prints a table, then the reasons of each failure; exits 1 if any case fails, 2 on bad
usage. The last line is exactly "N passed, M failed".
"""

import argparse
import json
import math
import os
import shlex
import subprocess
import sys
import tempfile

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hidden_effects as he  # noqa: E402

FLOOR_MM = math.sqrt(3.0) * he.NOISE_MM
BOUND_MM = 1.25 * FLOOR_MM
TAIL_LINES = 30


class CommandFailed(Exception):
    pass


def tail(text, n=TAIL_LINES):
    lines = text.rstrip("\n").splitlines()
    if len(lines) > n:
        lines = ["... (%d lines omitted)" % (len(lines) - n)] + lines[-n:]
    return "\n".join("      | " + l for l in lines) if lines else "      | (empty)"


def run_json(cmd, case_dir, tag, timeout):
    """Runs cmd, saves stdout/stderr as TAG.out/.err in case_dir, returns the parsed
    JSON object. Raises CommandFailed with a readable message otherwise."""
    shown = " ".join(shlex.quote(c) for c in cmd)
    try:
        proc = subprocess.run(cmd, cwd=case_dir, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, timeout=timeout)
    except subprocess.TimeoutExpired:
        raise CommandFailed("%s: no answer within %g s\n    $ %s" % (tag, timeout, shown))
    except OSError as e:
        raise CommandFailed("%s: cannot run: %s\n    $ %s" % (tag, e, shown))
    out = proc.stdout.decode("utf-8", "replace")
    err = proc.stderr.decode("utf-8", "replace")
    with open(os.path.join(case_dir, tag + ".out"), "w") as f:
        f.write(out)
    with open(os.path.join(case_dir, tag + ".err"), "w") as f:
        f.write(err)
    if proc.returncode != 0:
        what = {1: "computation failed", 2: "bad input or usage"}.get(proc.returncode, "")
        if proc.returncode < 0:
            what = "killed by signal %d" % -proc.returncode
        raise CommandFailed("%s: exit %d%s\n    $ %s\n    stderr:\n%s"
                            % (tag, proc.returncode, " (%s)" % what if what else "",
                               shown, tail(err)))
    try:
        obj = json.loads(out)
    except ValueError as e:
        raise CommandFailed("%s: stdout is not one JSON object (%s)\n    $ %s\n    stdout:\n%s"
                            "\n    stderr:\n%s" % (tag, e, shown, tail(out), tail(err)))
    if not isinstance(obj, dict):
        raise CommandFailed("%s: stdout is JSON but not an object\n    $ %s" % (tag, shown))
    return obj


def number(obj, key, tag):
    v = obj.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise CommandFailed("%s: key '%s' missing or not a finite number (got %r)"
                            % (tag, key, v))
    return float(v)


def candidate_label(c):
    eff = c.get("effect")
    j = c.get("joint")
    return "%s:%s" % (eff, j) if j is not None else str(eff)


def check_candidates(obj, scenario):
    """Returns (top candidate or None, list of failure reasons)."""
    cands = obj.get("candidates")
    if not isinstance(cands, list):
        return None, ["diagnose: 'candidates' missing or not a list (got %r)"
                      % (type(cands).__name__,)]
    for k, c in enumerate(cands):
        if not isinstance(c, dict) or "effect" not in c or "significant" not in c:
            return None, ["diagnose: candidates[%d] lacks 'effect'/'significant': %r" % (k, c)]
        if not isinstance(c["significant"], bool):
            return None, ["diagnose: candidates[%d].significant is not a bool: %r"
                          % (k, c["significant"])]
    top = cands[0] if cands else None
    reasons = []
    if scenario.name == "clean":
        sig = [candidate_label(c) for c in cands if c["significant"]]
        if sig:
            reasons.append("diagnose: clean data, but significant: %s" % ", ".join(sig))
        return top, reasons
    if top is None:
        return None, ["diagnose: no candidates at all (hidden %s)" % scenario.case]
    want_joint = scenario.joint  # None for measurer_scale
    got_joint = top.get("joint")
    if top.get("effect") != scenario.name or got_joint != want_joint:
        rank = [k + 1 for k, c in enumerate(cands)
                if c.get("effect") == scenario.name and c.get("joint") == want_joint]
        reasons.append("diagnose: first candidate is %s, hidden is %s (%s)"
                       % (candidate_label(top), scenario.case,
                          "ranked %d" % rank[0] if rank else "not listed"))
    elif not top["significant"]:
        reasons.append("diagnose: %s named first but not significant (explained %s)"
                       % (scenario.case, top.get("explained")))
    return top, reasons


def run_case(dhcal, work, case, seed, timeout):
    """dhcal: the command prefix (list) that runs the program."""
    res = {"case": case, "seed": seed, "top": None, "reasons": [], "base": None, "eff": None}
    case_dir = os.path.join(work, case.replace(":", "_"))
    try:
        sc = he.generate(case, seed, case_dir)
    except Exception as e:  # the generator is ours: report, do not hide
        res["reasons"].append("generator failed: %r" % (e,))
        return res
    res["size"] = sc.truth()["effect_size"]["tool_rms_mm"]
    common = ["--model", "model.json", "--data", "train.csv"]

    # 1. diagnose
    try:
        diag = run_json(dhcal + ["diagnose"] + common + ["--json"], case_dir, "diagnose",
                        timeout)
        top, reasons = check_candidates(diag, sc)
        res["top"] = top
        res["reasons"] += reasons
    except CommandFailed as e:
        res["reasons"].append(str(e))

    fit = dhcal + ["fit"] + common + ["--heldout", "heldout.csv"]
    # 2. fit with the hidden effect (clean: the base fit is the criterion)
    if sc.name != "clean":
        try:
            obj = run_json(fit + ["--effects", case, "--json"], case_dir, "fit_effect", timeout)
            res["eff"] = number(obj, "heldout_rms_mm", "fit --effects %s" % case)
            if res["eff"] > BOUND_MM:
                res["reasons"].append("fit --effects %s: held-out RMS %.4f mm > %.4f mm "
                                      "(1.25 x noise floor %.4f)"
                                      % (case, res["eff"], BOUND_MM, FLOOR_MM))
        except CommandFailed as e:
            res["reasons"].append(str(e))

    # 3. fit without effects: informational, except for clean data
    try:
        obj = run_json(fit + ["--json"], case_dir, "fit_base", timeout)
        res["base"] = number(obj, "heldout_rms_mm", "fit (no effects)")
        if sc.name == "clean":
            res["eff"] = res["base"]
            if res["base"] > BOUND_MM:
                res["reasons"].append("fit (clean data): held-out RMS %.4f mm > %.4f mm"
                                      % (res["base"], BOUND_MM))
    except CommandFailed as e:
        if sc.name == "clean":
            res["reasons"].append(str(e))
        else:
            res["notes"] = ["(informational) " + str(e)]
    return res


def fmt_rms(v):
    return "%.4f" % v if v is not None else "-"


def print_table(results):
    head = ("case", "seed", "size mm", "top candidate", "explained", "sig",
            "held-out RMS mm: base -> effect", "result")
    rows = []
    for r in results:
        top = r["top"]
        expl = top.get("explained") if top else None
        rows.append((
            r["case"], str(r["seed"]),
            "%.3f" % r["size"] if r.get("size") is not None else "-",
            candidate_label(top) if top else "-",
            "%.4f" % expl if isinstance(expl, (int, float)) and not isinstance(expl, bool)
            else "-",
            ("yes" if top["significant"] else "no") if top else "-",
            "%s -> %s" % (fmt_rms(r["base"]), fmt_rms(r["eff"])),
            "PASS" if not r["reasons"] else "FAIL"))
    widths = [max(len(x[k]) for x in rows + [head]) for k in range(len(head))]
    line = lambda cells: "  ".join(c.ljust(w) for c, w in zip(cells, widths)).rstrip()
    print(line(head))
    print(line(["-" * w for w in widths]))
    for row in rows:
        print(line(row))
    print("noise floor sqrt(3) x %.3f = %.4f mm; bound 1.25 x floor = %.4f mm; "
          "size = RMS hidden-effect displacement of the tool"
          % (he.NOISE_MM, FLOOR_MM, BOUND_MM))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dhcal", required=True, help="path of the dhcal executable")
    ap.add_argument("--work", help="directory for the generated data and outputs "
                                   "(default: a new temporary directory)")
    ap.add_argument("--seed", type=int, default=1,
                    help="base seed: case k (1-based) uses seed*100 + k (default 1)")
    ap.add_argument("--cases", help="comma-separated subset of the cases (default: all)")
    ap.add_argument("--timeout", type=float, default=600.0,
                    help="seconds allowed per dhcal command (default 600)")
    ap.add_argument("--wrapper", default="",
                    help="command prefix to run dhcal with (a cross build's emulator)")
    args = ap.parse_args(argv)

    dhcal = os.path.abspath(args.dhcal)
    if not (os.path.isfile(dhcal) and os.access(dhcal, os.X_OK)):
        print("run_acceptance: --dhcal %s is not an executable file" % args.dhcal,
              file=sys.stderr)
        return 2
    cases = list(he.CASES)
    if args.cases:
        cases = [c.strip() for c in args.cases.split(",") if c.strip()]
        unknown = [c for c in cases if c not in he.CASES]
        if unknown:
            print("run_acceptance: unknown case(s) %s; known: %s"
                  % (", ".join(unknown), ", ".join(he.CASES)), file=sys.stderr)
            return 2
    work = os.path.abspath(args.work) if args.work else tempfile.mkdtemp(prefix="dhcal-acc-")
    os.makedirs(work, exist_ok=True)
    print("dhcal acceptance: %s, work directory %s" % (dhcal, work))
    prefix = shlex.split(args.wrapper) + [dhcal]

    results = []
    for case in cases:
        seed = args.seed * 100 + he.CASES.index(case) + 1
        r = run_case(prefix, work, case, seed, args.timeout)
        results.append(r)
        print("  %-20s %s" % (case, "PASS" if not r["reasons"] else "FAIL"), flush=True)

    print()
    print_table(results)
    failed = [r for r in results if r["reasons"]]
    noted = [r for r in results if r.get("notes")]
    if failed or noted:
        print()
    for r in failed:
        print("FAIL %s (seed %d, data in %s):"
              % (r["case"], r["seed"], os.path.join(work, r["case"].replace(":", "_"))))
        for reason in r["reasons"]:
            print("  - " + reason)
    for r in noted:
        for note in r["notes"]:
            print("NOTE %s: %s" % (r["case"], note))
    print("%d passed, %d failed" % (len(results) - len(failed), len(failed)))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
