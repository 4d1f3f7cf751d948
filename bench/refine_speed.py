#!/usr/bin/env python3
"""`dhcal refine` on the real arms, timed, and its cross-validation by both methods in the same
run: the goal of issue #26 (refine on every set of the real-data folder within 2 s).

For every set of --realdata (ur5-jacobi and wam-jacobi as shipped, with their held-out rows;
ur10-ipa-a..d as shipped, with orientation and temperature columns, and with positions only;
the two held-out splits tests/realdata/test_realdata.py checks: UR10 D even -> odd rows and
B -> C, positions only):
  - `dhcal refine --effects base_frame,tool_offset --json`, a whole process, wall clock, the
    best of --repeat runs: seconds, the steps it chose, the held-out numbers;
  - bench_cv (bench/cv_speed.c) on the start fit (`dhcal fit --effects base_frame,tool_offset`):
    the CV RMS of the folds' estimates from the downdated normal equations
    (dhcal_cross_validate) and of their refits (dhcal_cross_validate_refit), their relative
    difference, the largest relative difference of a fold's sum of squares, the folds the
    fast method refitted, each method's time and the ratio.
Positions-only copies are written to a scratch directory (--scratch, default a temporary
one), never into the repository. Without the real-data folder the benchmark says so and
exits 0: there is nothing to measure.

Usage: refine_speed.py --dhcal build/host/tools/dhcal --bench-cv build/host/tests/bench_cv
                       [--realdata DIR] [--scratch DIR] [--repeat 3] [--goal-s 2]
Exit status 1 when a program fails or the two CV methods differ by more than --agree
(relative, default 0.005) on a start fit; the 2 s goal is reported met or not, it does not
change the exit status (a benchmark, not a timed test).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

# the real-data test's copy of a set with positions only (one definition for both)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tests',
                                'realdata'))
from test_realdata import positions_only  # noqa: E402

START = 'base_frame,tool_offset'


def cases(rd, scratch):
    """(label, model, data, held-out or None) for every set present."""
    out = []
    for name in ('ur5-jacobi', 'wam-jacobi'):
        d = os.path.join(rd, name)
        if os.path.isdir(d):
            held = os.path.join(d, 'heldout.csv')
            out.append((name, os.path.join(d, 'model.json'), os.path.join(d, 'data.csv'),
                        held if os.path.isfile(held) else None))
    for s in 'abcd':
        d = os.path.join(rd, 'ur10-ipa-' + s)
        if not os.path.isdir(d):
            continue
        model, data = os.path.join(d, 'model.json'), os.path.join(d, 'data.csv')
        pos = os.path.join(scratch, f'ur10-{s}-positions.csv')
        positions_only(data, pos)
        out.append((f'ur10-ipa-{s}', model, data, None))
        out.append((f'ur10-ipa-{s} positions', model, pos, None))
    d = os.path.join(rd, 'ur10-ipa-d')
    if os.path.isdir(d):
        even, odd = (os.path.join(scratch, f'ur10-d-{p}.csv') for p in ('even', 'odd'))
        positions_only(os.path.join(d, 'data.csv'), even, parity=0)
        positions_only(os.path.join(d, 'data.csv'), odd, parity=1)
        out.append(('ur10-ipa-d even -> odd', os.path.join(d, 'model.json'), even, odd))
    b, c = os.path.join(rd, 'ur10-ipa-b'), os.path.join(rd, 'ur10-ipa-c')
    if os.path.isdir(b) and os.path.isdir(c):
        out.append(('ur10-ipa-b -> c', os.path.join(b, 'model.json'),
                    os.path.join(scratch, 'ur10-b-positions.csv'),
                    os.path.join(scratch, 'ur10-c-positions.csv')))
    return out


def time_refine(dhcal, model, data, held, repeat):
    """Best wall-clock seconds of repeat whole `dhcal refine` processes, and its report."""
    args = [dhcal, 'refine', '--model', model, '--data', data, '--effects', START, '--json']
    if held:
        args += ['--heldout', held]
    best, report = None, None
    for _ in range(repeat):
        t0 = time.monotonic()
        r = subprocess.run(args, capture_output=True, text=True, timeout=900)
        dt = time.monotonic() - t0
        if r.returncode != 0:
            raise RuntimeError(f'refine exit {r.returncode}: {r.stderr.strip()}')
        report = json.loads(r.stdout)
        best = dt if best is None else min(best, dt)
    return best, report


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--dhcal', required=True)
    ap.add_argument('--bench-cv', required=True)
    ap.add_argument('--realdata', default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), '..', '..', 'shared', 'realdata'))
    ap.add_argument('--scratch', default=None)
    ap.add_argument('--repeat', type=int, default=3)
    ap.add_argument('--goal-s', type=float, default=2.0)
    ap.add_argument('--agree', type=float, default=0.005)
    a = ap.parse_args()
    rd = os.path.abspath(a.realdata)
    if not os.path.isdir(rd):
        print(f'SKIP: no real data at {rd} (the shared folder beside the repository): '
              'nothing to measure')
        return 0
    scratch = a.scratch or tempfile.mkdtemp(prefix='dhcal-refine-speed-')
    os.makedirs(scratch, exist_ok=True)
    failed = 0
    slow = []
    print(f'{"set":26s} {"rows":>6s} {"CV fast":>9s} {"CV refit":>9s} {"diff":>9s} '
          f'{"fold ss":>8s} {"fast s":>8s} {"refit s":>8s} {"ratio":>6s} {"refine s":>9s}  '
          'steps; held-out RMS / mean mm')
    for label, model, data, held in cases(rd, scratch):
        r = subprocess.run([a.bench_cv, '--model', model, '--data', data, '--effects', START,
                            '--repeat', str(a.repeat)], capture_output=True, text=True,
                           timeout=900)
        if r.returncode != 0:
            print(f'{label}: bench_cv failed: {r.stderr.strip()}')
            failed += 1
            continue
        cv = json.loads(r.stdout)
        try:
            secs, rep = time_refine(a.dhcal, model, data, held, a.repeat)
        except (RuntimeError, json.JSONDecodeError) as e:
            print(f'{label}: {e}')
            failed += 1
            continue
        steps = ' -> '.join(s['added'] or 'start' for s in rep.get('steps', []))
        held_txt = (f'; {rep["heldout_rms_mm"]:.4f} / {rep["heldout_mean_mm"]:.4f}'
                    if 'heldout_rms_mm' in rep else '')
        agree = abs(cv['cv_rel_diff']) <= a.agree and cv['fast_refit_folds'] == 0
        failed += 0 if agree else 1
        if secs > a.goal_s:
            slow.append(label)
        print(f'{label:26s} {cv["rows"]:6d} {cv["cv_fast_mm"]:9.5f} {cv["cv_refit_mm"]:9.5f} '
              f'{cv["cv_rel_diff"]:+9.1e} {cv["fold_ss_max_rel_diff"]:8.1e} '
              f'{cv["fast_s"]:8.4f} {cv["refit_s"]:8.4f} {cv["speedup"]:6.1f} {secs:9.2f}  '
              f'{steps}{held_txt}{"" if agree else "  (CV methods disagree)"}')
    print(f'refine within {a.goal_s:g} s on every set: '
          + ('met' if not slow else f'not met ({", ".join(slow)})'))
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
