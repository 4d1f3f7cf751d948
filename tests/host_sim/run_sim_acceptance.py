#!/usr/bin/env python3
"""Acceptance with the simulated arm: for every scenario of host_sim/scenarios/ with one
hidden physical effect, `dhcal diagnose` on a dhcal-sim dataset must name that effect first
(significant), and `dhcal fit` with it must reach the noise floor on held-out poses; on the
clean scenario nothing may be significant.

  run_sim_acceptance.py --sim PATH --dhcal PATH [--work DIR] [--seed S] [--timeout SEC]

Unlike tests/acceptance/ (effects added to the tool through dhcal's own model), here every
effect comes out of the plant's physics: stiffness under gravity, a dead zone, a gear's
transmission error, a gear ratio the controller does not know, a worn measuring wheel.
Per scenario (files written under --work/<scenario>/):
  1. dhcal-sim dataset: train.csv (60 poses, run seed 2S-1) and heldout.csv (40 poses, run
     seed 2S; S = --seed, default 1; the arm itself is fixed by the scenario file),
     model.json (--model-out); measurer_scale with --wires (raw wire lengths);
  2. dhcal diagnose --json: the first candidate is the scenario's effect and joint, and
     significant (clean: no candidate significant);
  3. dhcal fit --effects EFFECT --heldout: held-out RMS <= 1.25 x sqrt(3) x 0.05 mm, the
     noise floor of the scenarios' 0.05 mm noise (per coordinate, or per wire);
  4. dhcal fit without effects (the "before" figure).
Documented look-alikes (expect = None) are run and reported, never failed.
Prints a table and the reasons of each failure; exit 1 if any case fails, 2 on bad usage.
The last line is exactly "N passed, M failed".
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCENARIOS = os.path.join(ROOT, 'host_sim', 'scenarios')

NOISE_MM = 0.05
FLOOR_MM = math.sqrt(3.0) * NOISE_MM
BOUND_MM = 1.25 * FLOOR_MM

# scenario file -> (effect, joint or None, dataset options); effect None: look-alike, report only
CASES = [
    ('clean.json', ('clean', None), []),
    ('joint_compliance_2.json', ('joint_compliance', 2), []),
    ('joint_backlash_1.json', ('joint_backlash', 1), []),
    ('joint_harmonic_1.json', ('joint_harmonic', 1), []),
    ('joint_scale_1.json', ('joint_scale', 1), []),
    ('measurer_scale.json', ('measurer_scale', None), ['--wires']),
    ('measurer_offset.json', ('measurer_offset', None), ['--wires']),
    ('joint_backlash_2_loaded.json', None, []),
    ('measurer_anchors.json', None, ['--wires']),
]


class Failed(Exception):
    pass


def run(cmd, cwd, tag, timeout, want_json=True):
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, errors='replace',
                          timeout=timeout)
    with open(os.path.join(cwd, tag + '.out'), 'w') as f:
        f.write(proc.stdout)
    with open(os.path.join(cwd, tag + '.err'), 'w') as f:
        f.write(proc.stderr)
    if proc.returncode != 0:
        raise Failed('%s: exit %d\n    $ %s\n    %s' % (tag, proc.returncode, ' '.join(cmd),
                                                       proc.stderr.strip()[-2000:]))
    if not want_json:
        return None
    try:
        return json.loads(proc.stdout)
    except ValueError as e:
        raise Failed('%s: stdout is not JSON (%s)' % (tag, e))


def label(c):
    return '%s:%s' % (c['effect'], c['joint']) if c.get('joint') is not None else c['effect']


def run_case(sim, dhcal, work, name, expect, opts, seed, timeout):
    res = {'case': name[:-5], 'expect': expect, 'top': None, 'base': None, 'eff': None,
           'reasons': []}
    d = os.path.join(work, name[:-5])
    os.makedirs(d, exist_ok=True)
    scen = os.path.join(SCENARIOS, name)
    try:
        run([sim, 'dataset', '--scenario', scen, '--poses', '60', '--seed', str(2 * seed - 1),
             '--out',
             'train.csv', '--model-out', 'model.json'] + opts, d, 'sim_train', timeout, False)
        run([sim, 'dataset', '--scenario', scen, '--poses', '40', '--seed', str(2 * seed),
             '--out',
             'heldout.csv'] + opts, d, 'sim_heldout', timeout, False)
        common = ['--model', 'model.json', '--data', 'train.csv']
        diag = run([dhcal, 'diagnose'] + common + ['--json'], d, 'diagnose', timeout)
        cands = diag.get('candidates')
        if not isinstance(cands, list):
            raise Failed('diagnose: no candidates list')
        res['top'] = cands[0] if cands else None
        fit = [dhcal, 'fit'] + common + ['--heldout', 'heldout.csv', '--json']
        res['base'] = run(fit, d, 'fit_base', timeout)['heldout_rms_mm']
        if expect is None:
            return res
        effect, joint = expect
        if effect == 'clean':
            sig = [label(c) for c in cands if c.get('significant')]
            if sig:
                res['reasons'].append('clean data, but significant: ' + ', '.join(sig))
            res['eff'] = res['base']
        else:
            top = res['top']
            if top is None or top.get('effect') != effect or top.get('joint') != joint:
                rank = [k + 1 for k, c in enumerate(cands)
                        if c.get('effect') == effect and c.get('joint') == joint]
                res['reasons'].append('first candidate %s, hidden %s (%s)' % (
                    label(top) if top else 'none', label({'effect': effect, 'joint': joint}),
                    'ranked %d' % rank[0] if rank else 'not listed'))
            elif not top.get('significant'):
                res['reasons'].append('%s named first but not significant' % label(top))
            arg = effect if joint is None else '%s:%d' % (effect, joint)
            res['eff'] = run(fit + ['--effects', arg], d, 'fit_effect', timeout)['heldout_rms_mm']
        if res['eff'] is not None and res['eff'] > BOUND_MM:
            res['reasons'].append('held-out RMS %.4f mm > %.4f mm (1.25 x noise floor)'
                                  % (res['eff'], BOUND_MM))
    except (Failed, subprocess.TimeoutExpired, OSError) as e:
        res['reasons'].append(str(e))
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--sim', required=True, help='the dhcal-sim executable')
    ap.add_argument('--dhcal', required=True, help='the dhcal executable')
    ap.add_argument('--work', help='directory for data and outputs (default: a temporary one)')
    ap.add_argument('--seed', type=int, default=1, help='run seeds 2S-1 (train), 2S (held out)')
    ap.add_argument('--timeout', type=float, default=300.0)
    args = ap.parse_args()
    for exe in (args.sim, args.dhcal):
        if not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
            print('run_sim_acceptance: %s is not an executable file' % exe, file=sys.stderr)
            return 2
    work = os.path.abspath(args.work) if args.work else tempfile.mkdtemp(prefix='dhcal-simacc-')
    os.makedirs(work, exist_ok=True)
    print('dhcal acceptance on dhcal-sim data: work directory %s' % work)
    results = []
    for name, expect, opts in CASES:
        r = run_case(os.path.abspath(args.sim), os.path.abspath(args.dhcal), work, name, expect,
                     opts, args.seed, args.timeout)
        results.append(r)
        verdict = 'info' if expect is None else ('PASS' if not r['reasons'] else 'FAIL')
        print('  %-26s %s' % (r['case'], verdict), flush=True)

    head = ('scenario', 'hidden effect', 'named first', 'explained', 'sig',
            'held-out RMS mm: base -> effect', 'result')
    rows = []
    for r in results:
        top = r['top']
        exp = r['expect']
        rows.append((
            r['case'],
            '-' if exp is None else (exp[0] if exp[1] is None else '%s:%d' % exp),
            label(top) if top else '-',
            '%.3f' % top['explained'] if top and isinstance(top.get('explained'), (int, float))
            else '-',
            ('yes' if top.get('significant') else 'no') if top else '-',
            '%s -> %s' % ('%.4f' % r['base'] if r['base'] is not None else '-',
                          '%.4f' % r['eff'] if r['eff'] is not None else '-'),
            'info' if exp is None else ('PASS' if not r['reasons'] else 'FAIL')))
    widths = [max(len(x[k]) for x in rows + [head]) for k in range(len(head))]
    fmt = lambda cells: '  '.join(c.ljust(w) for c, w in zip(cells, widths)).rstrip()
    print()
    print(fmt(head))
    print(fmt(['-' * w for w in widths]))
    for row in rows:
        print(fmt(row))
    print('noise 0.05 mm per coordinate (or wire): floor sqrt(3) x 0.05 = %.4f mm, bound '
          '%.4f mm' % (FLOOR_MM, BOUND_MM))
    failed = [r for r in results if r['expect'] is not None and r['reasons']]
    for r in results:
        if r['reasons']:
            print('%s %s (data in %s):' % ('FAIL' if r in failed else 'NOTE', r['case'],
                                          os.path.join(work, r['case'])))
            for reason in r['reasons']:
                print('  - ' + reason)
    judged = [r for r in results if r['expect'] is not None]
    print('%d passed, %d failed' % (len(judged) - len(failed), len(failed)))
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
