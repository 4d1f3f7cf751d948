#!/usr/bin/env python3
"""The dhcal-sim program as a person runs it: exit codes, one message naming the scenario
file and the JSON path for every defect, --out never touched by a failed run, identical
bytes for identical arguments, the CSV contract of docs/formats.md, sections 3 and 4.2.

Usage: test_sim_cli.py --sim PATH [--dhcal PATH]
  Scenarios are copied from host_sim/scenarios/ and mutated per case in a temporary
  directory. With --dhcal, the written model and dataset are also read by dhcal compare.
"""
import argparse
import copy
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCENARIOS = os.path.join(ROOT, 'host_sim', 'scenarios')
SIM = None
DHCAL = None



def read(path, mode='r'):
    with open(path, mode) as f:
        return f.read()


CLEAN = json.loads(read(os.path.join(SCENARIOS, 'clean.json')))
MODEL_TEXT = read(os.path.join(SCENARIOS, 'paper-3dof-model.json'))
COUNT_DEG = 360.0 / 200000.0  # one encoder count at the joint


class SimCli(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix='dhcal-sim-cli-')
        self.write('paper-3dof-model.json', MODEL_TEXT)
        self.out = os.path.join(self.dir, 'data.csv')

    def tearDown(self):
        shutil.rmtree(self.dir)

    def write(self, name, text):
        path = os.path.join(self.dir, name)
        with open(path, 'w') as f:
            f.write(text)
        return path

    def scenario(self, obj=None, text=None, name='s.json'):
        return self.write(name, text if text is not None else json.dumps(obj or CLEAN))

    def sim(self, *args):
        return subprocess.run([SIM, *args], capture_output=True, text=True, errors='replace',
                              timeout=120)

    def dataset(self, scenario, *extra, poses='5'):
        return self.sim('dataset', '--scenario', scenario, '--poses', poses, '--out', self.out,
                        *extra)

    def assert_bad(self, result, *must_contain):
        self.assertEqual(result.returncode, 2, result.stdout + result.stderr)
        lines = [l for l in result.stderr.splitlines() if l.strip()]
        self.assertTrue(lines and lines[0].startswith('dhcal-sim: '), result.stderr)
        for text in must_contain:
            self.assertIn(text, lines[0])
        self.assertFalse(os.path.exists(self.out), 'a failed run created --out')

    # ------------------------------------------------------------ bad scenario files
    def mutated(self, change):
        s = copy.deepcopy(CLEAN)
        change(s)
        return self.scenario(s)

    def test_missing_keys_are_named(self):
        for key in ('seed', 'model', 'joints'):
            path = self.mutated(lambda s, k=key: s.pop(k))
            self.assert_bad(self.dataset(path), path, ': %s: required key missing' % key)
        path = self.mutated(lambda s: s['joints'][1]['link'].pop('mass_kg'))
        self.assert_bad(self.dataset(path), path, ': joints[1].link.mass_kg: required key missing')
        path = self.mutated(lambda s: s['joints'][2].pop('link'))
        self.assert_bad(self.dataset(path), path, ': joints[2].link: required key missing')

    def test_negative_masses_and_stiffness_are_refused(self):
        cases = [
            (lambda s: s['joints'][1]['link'].__setitem__('mass_kg', -1.0),
             'joints[1].link.mass_kg', 'must be >= 0'),
            (lambda s: s['joints'][1].__setitem__('gear', {'stiffness_nm_per_rad': -5}),
             'joints[1].gear.stiffness_nm_per_rad', 'must be > 0'),
            (lambda s: s['payload'].__setitem__('mass_kg', -0.5), 'payload.mass_kg', '>= 0'),
            (lambda s: s['joint_defaults']['motor'].__setitem__('r_ohm', 0),
             'joint_defaults.motor.r_ohm', 'must be > 0'),
            (lambda s: s['joints'][0]['link'].__setitem__('inertia_kgm2', [0.1, -0.1, 0.1]),
             'joints[0].link.inertia_kgm2[1]', '>= 0'),
            (lambda s: s['measurer'].__setitem__('noise_mm', -1), 'measurer.noise_mm', '>= 0'),
        ]
        for change, where, why in cases:
            path = self.mutated(change)
            self.assert_bad(self.dataset(path), path, where, why)

    def test_nan_and_infinity_are_refused_with_their_path(self):
        text = json.dumps(CLEAN).replace('"ratio": 100', '"ratio": NaN')
        path = self.scenario(text=text)
        self.assert_bad(self.dataset(path), path, 'joint_defaults.gear.ratio', 'NaN')
        text = json.dumps(CLEAN).replace('"mass_kg": 3.8', '"mass_kg": -Infinity')
        path = self.scenario(text=text)
        self.assert_bad(self.dataset(path), path, 'joints[1].link.mass_kg', 'Infinity')
        text = json.dumps(CLEAN).replace('"mass_kg": 1.5', '"mass_kg": 1e999')
        path = self.scenario(text=text)
        self.assert_bad(self.dataset(path), path, 'joints[2].link.mass_kg', 'finite')

    def test_wrong_types_are_named(self):
        cases = [
            (lambda s: s.__setitem__('seed', 'one'), 'seed', 'got a string'),
            (lambda s: s.__setitem__('seed', 1.5), 'seed', '1.5 is not a whole number'),
            (lambda s: s.__setitem__('joints', {}), 'joints', 'expected an array'),
            (lambda s: s['joints'][2]['link'].__setitem__('com_mm', 'x'),
             'joints[2].link.com_mm', 'array of 3 numbers'),
            (lambda s: s['joints'][0].__setitem__('motor', [1, 2]), 'joints[0].motor',
             'expected an object'),
            (lambda s: s['joint_defaults']['encoder'].__setitem__('lines', 500.5),
             'joint_defaults.encoder.lines', '500.5 is not a whole number'),
            (lambda s: s['noise'].__setitem__('xyz_mm', True), 'noise.xyz_mm', 'boolean'),
            (lambda s: s.__setitem__('model', 7), 'model', 'path of a model file'),
        ]
        for change, where, why in cases:
            path = self.mutated(change)
            self.assert_bad(self.dataset(path), path, where, why)

    def test_structure_defects_are_named(self):
        cases = [
            (lambda s: s['joints'].pop(), 'joints', 'expected 3 entries'),
            (lambda s: s['joints'][0]['motor'].__setitem__('resistance', 1) if 'motor' in
             s['joints'][0] else s['joints'][0].__setitem__('motor', {'resistance': 1}),
             'joints[0].motor.resistance', 'unknown key'),
            (lambda s: s['joints'][0].__setitem__('gear', {'backlash_deg': 0.1}),
             'joints[0]', 'backlash needs a finite stiffness'),
            (lambda s: s['joints'][0].__setitem__(
                'gear', {'stiffness_nm_per_rad': 1e4,
                         'transmission_error': [{'order': 0, 'sin_mrad': 1}]}),
             'joints[0].gear.transmission_error[0].order', '0 is outside [1, 1000]'),
            (lambda s: s.__setitem__('physics', {'step_us': 150}), 'physics.step_us',
             '10 kHz or finer'),
            (lambda s: s['measurer'].__setitem__('wheel_radius_error', 0.7),
             'measurer.wheel_radius_error', 'within'),
            (lambda s: s.__setitem__('model', 'no-such-model.json'), 'model', 'no-such-model'),
            (lambda s: s['truth']['joints'].pop(), 'truth.joints', 'one per joint'),
        ]
        for change, where, why in cases:
            path = self.mutated(change)
            self.assert_bad(self.dataset(path), path, where, why)

    def test_syntax_errors_and_duplicates(self):
        path = self.scenario(text='{"seed": 1,\n  "model": "paper-3dof-model.json",\n  oops}')
        self.assert_bad(self.dataset(path), path + ':3:', 'syntax error')
        path = self.scenario(text='{"seed": 1, "seed": 2}')
        self.assert_bad(self.dataset(path), path, ': seed: key repeated')
        path = self.scenario(text='[1, 2]')
        self.assert_bad(self.dataset(path), path, 'expected an object')
        path = self.scenario(text='')
        self.assert_bad(self.dataset(path), path, 'empty file')
        self.assert_bad(self.dataset(os.path.join(self.dir, 'missing.json')), 'missing.json',
                        'cannot open')

    def test_failed_run_leaves_out_untouched(self):
        with open(self.out, 'w') as f:
            f.write('precious\n')
        path = self.mutated(lambda s: s.pop('seed'))
        r = self.dataset(path)
        self.assertEqual(r.returncode, 2)
        self.assertEqual(read(self.out), 'precious\n')

    # ------------------------------------------------------------ usage
    def test_usage_errors_exit_2(self):
        good = self.scenario()
        for args in ([], ['simulate'], ['dataset'], ['dataset', '--scenario', good],
                     ['dataset', '--scenario', good, '--out', self.out],
                     ['dataset', '--scenario', good, '--out', self.out, '--poses', '0'],
                     ['dataset', '--scenario', good, '--out', self.out, '--poses', 'ten'],
                     ['dataset', '--scenario', good, '--out', self.out, '--poses', '5',
                      '--plan', good],
                     ['dataset', '--scenario', good, '--out', self.out, '--poses', '5',
                      '--seed', '-1'],
                     ['dataset', '--scenario', good, '--out', self.out, '--poses', '5', '--x']):
            r = self.sim(*args)
            self.assertEqual(r.returncode, 2, (args, r.stderr))
            self.assertIn('usage', r.stderr)
        for args in (['--help'], ['dataset', '--help']):
            r = self.sim(*args)
            self.assertEqual(r.returncode, 0)
            self.assertIn('--scenario', r.stdout)
            self.assertIn('--wires', r.stdout)

    def test_usage_errors_name_the_option(self):
        good = self.scenario()
        base = ['dataset', '--scenario', good, '--out', self.out, '--poses', '5']
        for args, words in ((base + ['stray'], "unexpected argument 'stray'"),
                            (base + ['--seed'], '--seed needs a value'),
                            (base + ['--out', self.out], '--out given twice'),
                            (['bus', '--can', 'vcan0', 'stray'],
                             "bus: unexpected argument 'stray'"),
                            (['bus', '--cann', 'vcan0'], "bus: unknown option '--cann'")):
            r = self.sim(*args)
            self.assertEqual(r.returncode, 2, (args, r.stderr))
            self.assertIn(words, r.stderr, args)
        self.assertFalse(os.path.exists(self.out))

    def test_option_value_after_an_equals_sign(self):
        good = self.scenario()
        spaced = self.sim('dataset', '--scenario', good, '--out', self.out, '--poses', '5')
        self.assertEqual(spaced.returncode, 0, spaced.stderr)
        first = read(self.out)
        os.remove(self.out)
        joined = self.sim('dataset', '--scenario=' + good, '--out=' + self.out, '--poses=5')
        self.assertEqual(joined.returncode, 0, joined.stderr)
        self.assertEqual(read(self.out), first)

    # ------------------------------------------------------------ good runs
    def read_csv(self, path):
        rows = []
        header = None
        for line in read(path).splitlines():
            if line.startswith('#'):
                continue
            cells = line.strip().split(',')
            if header is None:
                header = cells
            else:
                rows.append(dict(zip(header, map(float, cells))))
        return header, rows

    def test_dataset_follows_the_csv_contract(self):
        good = self.scenario()
        r = self.dataset(good, poses='40')
        self.assertEqual(r.returncode, 0, r.stderr)
        header, rows = self.read_csv(self.out)
        self.assertEqual(header, ['q1', 'q2', 'q3', 'dir1', 'dir2', 'dir3', 'x', 'y', 'z'])
        self.assertEqual(len(rows), 40)
        model = json.loads(MODEL_TEXT)
        for row in rows:
            for j in range(3):
                q = row['q%d' % (j + 1)]
                # whole encoder counts, inside the model's range
                self.assertAlmostEqual(q / COUNT_DEG, round(q / COUNT_DEG), places=4)
                self.assertGreaterEqual(q, model['joints'][j]['min_deg'] - COUNT_DEG)
                self.assertLessEqual(q, model['joints'][j]['max_deg'] + COUNT_DEG)
                self.assertIn(row['dir%d' % (j + 1)], (-1.0, 1.0))
        r = self.dataset(good, '--wires', poses='10')
        self.assertEqual(r.returncode, 0, r.stderr)
        header, rows = self.read_csv(self.out)
        self.assertEqual(header[-3:], ['L1', 'L2', 'L3'])
        self.assertTrue(all(500.0 < row['L1'] < 2500.0 for row in rows))

    def test_same_arguments_give_identical_bytes(self):
        good = self.scenario(json.loads(read(os.path.join(SCENARIOS, 'joint_backlash_1.json'))))
        for extra in ([], ['--wires']):
            outs = []
            for k in range(2):
                out = os.path.join(self.dir, 'run%d.csv' % k)
                r = self.sim('dataset', '--scenario', good, '--poses', '60', '--seed', '7',
                             '--out', out, *extra)
                self.assertEqual(r.returncode, 0, r.stderr)
                outs.append(read(out, 'rb'))
            self.assertEqual(outs[0], outs[1])
        other = os.path.join(self.dir, 'other.csv')
        r = self.sim('dataset', '--scenario', good, '--poses', '60', '--seed', '8', '--out', other)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertNotEqual(read(other, 'rb'), outs[0])

    def test_payload_sits_at_the_true_tool_point_by_default(self):
        # A payload loads the compliant joint 2 through its moment arm: where its centre of
        # mass sits shows in the deflection. Without com_mm it is the true tool point, the
        # nominal one (here the origin of the last frame) moved by truth.tool_mm.
        base = json.loads(read(os.path.join(SCENARIOS, 'joint_compliance_2.json')))
        base.setdefault('truth', {})['tool_mm'] = [80.0, 0.0, -40.0]
        rows = {}
        for label, com in (('default', None), ('true', [80.0, 0.0, -40.0]),
                           ('nominal', [0.0, 0.0, 0.0])):
            sc = copy.deepcopy(base)
            sc['payload'] = {'mass_kg': 5.0}
            if com is not None:
                sc['payload']['com_mm'] = com
            r = self.dataset(self.scenario(sc), poses='20')
            self.assertEqual(r.returncode, 0, r.stderr)
            rows[label] = [l for l in read(self.out).splitlines() if not l.startswith('#')]
        self.assertEqual(rows['default'], rows['true'])
        self.assertNotEqual(rows['default'], rows['nominal'])

    def test_plan_gives_the_targets_and_directions(self):
        good = self.scenario()
        plan = self.write('plan.csv', '# targets\nq1, q2, q3, dir2\n10, 45, -30, -1\n'
                                      '-120.5, 100, 60, 1\n')
        r = self.sim('dataset', '--scenario', good, '--plan', plan, '--out', self.out)
        self.assertEqual(r.returncode, 0, r.stderr)
        _, rows = self.read_csv(self.out)
        self.assertEqual(len(rows), 2)
        for row, want in zip(rows, [(10, 45, -30, -1), (-120.5, 100, 60, 1)]):
            for j in range(3):
                self.assertAlmostEqual(row['q%d' % (j + 1)], want[j], delta=COUNT_DEG)
            self.assertEqual(row['dir2'], want[3])
        bad = self.write('bad.csv', 'q1,q2\n1,2\n')
        r = self.sim('dataset', '--scenario', good, '--plan', bad, '--out', self.out)
        self.assertEqual(r.returncode, 2)
        self.assertIn("bad.csv:1: missing column 'q3'", r.stderr)

    def test_exact_gives_the_true_point_at_the_plan(self):
        # --exact, to judge commands: the plan's angles reported as they are (no count
        # rounding), no noise: every run seed gives the same points; a measuring run is
        # those points plus the scenario's 0.05 mm noise.
        good = self.scenario(json.loads(read(os.path.join(SCENARIOS, 'joint_compliance_2.json'))))
        # (directions given: the links' friction makes the rest pose depend on them)
        plan = self.write('plan.csv', 'q1,q2,q3,dir1,dir2,dir3\n10.123456789,45,-30,1,1,1\n'
                                      '-120.5,100.0000004,60,-1,1,-1\n')
        runs = []
        for seed in ('1', '2'):
            r = self.sim('dataset', '--scenario', good, '--plan', plan, '--exact', '--seed', seed,
                         '--out', self.out)
            self.assertEqual(r.returncode, 0, r.stderr)
            runs.append(self.read_csv(self.out)[1])
        for a, b in zip(*runs):
            self.assertEqual([a[k] for k in 'xyz'], [b[k] for k in 'xyz'])
        self.assertEqual([runs[0][0]['q1'], runs[0][1]['q2']], [10.123456789, 100.0000004])
        r = self.sim('dataset', '--scenario', good, '--plan', plan, '--out', self.out)
        self.assertEqual(r.returncode, 0, r.stderr)
        measured = self.read_csv(self.out)[1]
        for exact, noisy in zip(runs[0], measured):
            d = [abs(exact[k] - noisy[k]) for k in 'xyz']
            self.assertTrue(0.0 < max(d) < 0.3, d)  # noise (and the count), not another arm
        for extra in (['--plan', plan, '--wires'], ['--poses', '3']):
            r = self.sim('dataset', '--scenario', good, '--exact', '--out', self.out, *extra)
            self.assertEqual(r.returncode, 2)
            self.assertIn('--exact needs --plan', r.stderr)

    def test_model_out_loads_in_dhcal(self):
        good = self.scenario()
        model = os.path.join(self.dir, 'nominal.json')
        r = self.dataset(good, '--model-out', model, poses='30')
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(json.loads(read(model))['joints'][1]['a_mm'], 400)
        if DHCAL:
            c = subprocess.run([DHCAL, 'compare', '--model', model, '--data', self.out, '--json'],
                               capture_output=True, text=True, timeout=120)
            self.assertEqual(c.returncode, 0, c.stderr)
            rms = json.loads(c.stdout)['rms_mm']
            # the drawing against the arm as built: machining errors, ~ 1..10 mm
            self.assertTrue(0.3 < rms < 20.0, rms)


def main():
    global SIM, DHCAL
    ap = argparse.ArgumentParser()
    ap.add_argument('--sim', required=True)
    ap.add_argument('--dhcal')
    args, rest = ap.parse_known_args()
    SIM = os.path.abspath(args.sim)
    DHCAL = os.path.abspath(args.dhcal) if args.dhcal else None
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=1)


if __name__ == '__main__':
    main()
