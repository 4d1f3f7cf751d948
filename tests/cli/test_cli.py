#!/usr/bin/env python3
"""The dhcal program as a person runs it: exit codes, messages naming file and line, and
--out never created, truncated or overwritten by a failed run (docs/cli.md, 1.3).

Usage: test_cli.py --dhcal PATH [--wrapper 'CMD ARGS']
  (the data come from examples/ and are written per case). --wrapper runs every dhcal
  invocation under CMD, e.g. 'valgrind --error-exitcode=99 --leak-check=full': a wrapper
  that reports through its own exit code then fails the case's exit-code assertion.
"""
import json
import math
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
EXAMPLE = os.path.join(ROOT, 'examples', 'data', 'compliance')
DHCAL = None
WRAPPER = []

GOOD_MODEL = open(os.path.join(EXAMPLE, 'model.json')).read()
GOOD_CSV = open(os.path.join(EXAMPLE, 'train.csv')).read()
HEADER = 'q1,q2,q3,x,y,z'


def rot_from_rpy_deg(rpy_deg):
    """R = Rz(yaw) Ry(pitch) Rx(roll) (docs/formats.md, section 1), as nested lists."""
    r, p, y = (math.radians(v) for v in rpy_deg)
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    cy, sy = math.cos(y), math.sin(y)
    return [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr]]


def rotation_vector_deg(r):
    """Axis times angle (deg) of a rotation below a half turn."""
    angle = math.acos(max(-1.0, min(1.0, (r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0)))
    skew = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]]
    k = angle / (2.0 * math.sin(angle)) if angle > 1e-12 else 0.5
    return [math.degrees(k * v) for v in skew]


class Cli(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix='dhcal-cli-')
        self.model = self.write('model.json', GOOD_MODEL)
        self.data = self.write('train.csv', GOOD_CSV)
        self.out = os.path.join(self.dir, 'calibrated.json')

    def tearDown(self):
        shutil.rmtree(self.dir)

    def write(self, name, text, mode='w'):
        path = os.path.join(self.dir, name)
        with open(path, mode) as f:
            f.write(text)
        return path

    def run_dhcal(self, *args):
        return subprocess.run([*WRAPPER, DHCAL, *args], capture_output=True, text=True,
                              errors='replace', timeout=600 if WRAPPER else 120)

    def fit(self, model=None, data=None, *extra):
        return self.run_dhcal('fit', '--model', model or self.model, '--data', data or self.data,
                              '--out', self.out, *extra)

    def assert_bad_input(self, result, *must_contain):
        self.assertEqual(result.returncode, 2, result.stderr)
        lines = [l for l in result.stderr.splitlines() if l.startswith('dhcal: ')]
        self.assertEqual(len(lines), 1, result.stderr)
        for text in must_contain:
            self.assertIn(text, lines[0])

    def assert_out_untouched(self, before):
        if before is None:
            self.assertFalse(os.path.exists(self.out), 'a failed run created --out')
            leftovers = [f for f in os.listdir(self.dir) if f.startswith('calibrated')]
            self.assertEqual(leftovers, [], 'a failed run left a temporary file')
        else:
            with open(self.out) as f:
                self.assertEqual(f.read(), before, 'a failed run changed --out')

    # ---- bad CSV: each gets exit 2, one message with file and line, --out untouched
    def check_bad_csv(self, text, line, *words, binary=False):
        for existing in (None, '{"keep": "me"}\n'):
            if existing is None:
                if os.path.exists(self.out):
                    os.remove(self.out)
            else:
                self.write('calibrated.json', existing)
            data = self.write('bad.csv', text, 'wb' if binary else 'w')
            result = self.fit(None, data)
            self.assert_bad_input(result, 'bad.csv:%d' % line if line else 'bad.csv', *words)
            self.assert_out_untouched(existing)

    def test_empty_file(self):
        self.check_bad_csv('', 0)

    def test_header_without_rows(self):
        self.check_bad_csv('# only a header\n' + HEADER + '\n', 0)

    def test_short_row(self):
        self.check_bad_csv(HEADER + '\n1,2,3,4,5,6\n1,2,3,4,5\n', 3)

    def test_not_a_number(self):
        self.check_bad_csv(HEADER + '\n1,2,abc,4,5,6\n', 2, 'q3')

    def test_nan_and_inf(self):
        self.check_bad_csv(HEADER + '\n1,2,3,nan,5,6\n', 2, 'x')
        self.check_bad_csv(HEADER + '\n1,2,3,4,-inf,6\n', 2, 'y')
        self.check_bad_csv(HEADER + '\n1,2,3,4,5,1e999\n', 2, 'z')

    def test_values_beyond_physical_range(self):
        self.check_bad_csv(HEADER + '\n1,2,3000,4,5,6\n', 2, 'q3')
        self.check_bad_csv(HEADER + '\n1,2,3,4,5,6e9\n', 2, 'z')

    def test_unknown_and_repeated_columns(self):
        self.check_bad_csv('q1,q2,q3,x,y,z,colour\n1,2,3,4,5,6,7\n', 1, 'colour')
        self.check_bad_csv('q1,q2,q3,x,y,z,x\n1,2,3,4,5,6,7\n', 1, "'x'")

    def test_missing_joint_column_and_joint_beyond_the_model(self):
        self.check_bad_csv('q1,q3,x,y,z\n1,3,4,5,6\n', 1, 'q2')
        self.check_bad_csv('q1,q2,q3,q4,x,y,z\n1,2,3,4,5,6,7\n', 1, 'q4')

    def test_binary_garbage(self):
        self.check_bad_csv(b'q1,q2,q3,x,y,z\n\x00\x01\xff\xfe garbage\n', 2, binary=True)

    def test_one_megabyte_line(self):
        self.check_bad_csv(HEADER + '\n' + '1' * (1 << 20) + '\n', 2)

    # ---- bad model JSON: exit 2, file and JSON path or line:column
    def check_bad_model(self, text, *words):
        self.write('calibrated.json', 'previous calibration\n')
        model = self.write('bad.json', text)
        result = self.fit(model)
        self.assert_bad_input(result, 'bad.json', *words)
        self.assert_out_untouched('previous calibration\n')

    def test_broken_json(self):
        self.check_bad_model('{"joints": [ {"alpha_deg": 90, ', )

    def test_wrong_json_types(self):
        model = json.loads(GOOD_MODEL)
        model['joints'][1]['a_mm'] = "four hundred"
        self.check_bad_model(json.dumps(model), 'joints[1].a_mm')

    def test_joint_count_above_the_limit(self):
        model = json.loads(GOOD_MODEL)
        model['joints'] = [model['joints'][0]] * 8
        self.check_bad_model(json.dumps(model), 'joints')

    def test_effect_values_of_the_wrong_count(self):
        model = json.loads(GOOD_MODEL)
        model['effects'] = {'joint_compliance:2': [1e-4]}
        self.check_bad_model(json.dumps(model), 'joint_compliance:2')

    # ---- usage errors
    def test_usage_errors_exit_2(self):
        for args in (['fit'], ['fly', '--model', self.model, '--data', self.data],
                     ['fit', '--model', self.model, '--data', self.data, '--bogus'],
                     ['fit', '--model', self.model, '--data', self.data, '--effects', 'gremlins'],
                     ['fit', '--model', self.model, '--data', self.data, '--effects',
                      'joint_scale:9']):
            self.assertEqual(self.run_dhcal(*args).returncode, 2, args)

    def test_usage_errors_name_the_option(self):
        base = ['fit', '--model', self.model, '--data', self.data]
        for args, words in ((base + ['--out'], ("'--out' needs a value",)),
                            (base + ['--model', self.model], ("'--model' given twice",)),
                            (base + ['stray'], ("unexpected argument 'stray'",)),
                            (base + ['--cv=yes'], ("unknown option '--cv=yes'",))):
            r = self.run_dhcal(*args)
            self.assertEqual(r.returncode, 2, args)
            for w in words:
                self.assertIn(w, r.stderr, args)
            self.assertIn('usage: dhcal', r.stderr, args)

    def test_option_value_after_an_equals_sign(self):
        spaced = self.run_dhcal('compare', '--model', self.model, '--data', self.data, '--json')
        joined = self.run_dhcal('compare', '--model=' + self.model, '--data=' + self.data,
                                '--json')
        self.assertEqual(spaced.returncode, 0, spaced.stderr)
        self.assertEqual(joined.returncode, 0, joined.stderr)
        self.assertEqual(json.loads(joined.stdout)['rms_mm'],
                         json.loads(spaced.stdout)['rms_mm'])

    def test_version_is_the_library_header_s(self):
        header = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'lib',
                              'include', 'dhcal', 'dhc_version.h')
        with open(header) as f:
            parts = {k: v for k, v in re.findall(r'#define DHCAL_VERSION_(MAJOR|MINOR|PATCH) (\d+)',
                                                f.read())}
        r = self.run_dhcal('--version')
        self.assertEqual(r.returncode, 0)
        self.assertEqual(r.stdout.strip(),
                         'dhcal %s.%s.%s' % (parts['MAJOR'], parts['MINOR'], parts['PATCH']))

    def test_a_semicolon_separated_file_is_named_as_such(self):
        rows = [l for l in GOOD_CSV.splitlines() if not l.startswith('#')]
        semi = '\n'.join(l.replace(',', ';') for l in rows[:5]) + '\n'
        data = self.write('semicolons.csv', semi)
        r = self.run_dhcal('compare', '--model', self.model, '--data', data)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("semicolons.csv:1: unknown column", r.stderr)
        self.assertIn("separated by ';'", r.stderr)

    def test_bad_noise_models_exit_2_and_leave_out_untouched(self):
        for bad in ('0.001', 'x,0.01', '0.001,0', '0.001,-1', '-0.001,0.01', '2,0.01',
                    'nan,0.01', '0.001,inf', '0.001,0.01,3', '0.001,1e3'):
            r = self.fit(None, None, '--noise', bad)
            self.assert_bad_input(r, '--noise', bad)
            self.assert_out_untouched(None)

    def test_a_noise_model_weights_the_fit_and_reports_itself(self):
        r = self.fit(None, None, '--effects', 'joint_compliance:2', '--noise', '0.001,0.05',
                     '--json')
        self.assertEqual(r.returncode, 0, r.stderr)
        d = json.loads(r.stdout)
        self.assertEqual(d['noise_model']['joint_deg'], 0.001)
        self.assertEqual(d['noise_model']['meas_mm'], 0.05)
        self.assertNotIn('sigma_mm', d)
        # the fixture's noise is 0.05 mm per coordinate: the whitened sd is near 1
        self.assertGreater(d['noise_model']['whitened_sd'], 0.5)
        self.assertLess(d['noise_model']['whitened_sd'], 2.0)

    # ---- dhcal plan
    def plan(self, *extra):
        return self.run_dhcal('plan', '--model', self.model, '--out', self.out, *extra)

    def test_plan_bad_input_exits_2_and_leaves_out_untouched(self):
        cases = [(('--poses', '0'), '--poses'), (('--poses', 'x'), '--poses'),
                 (('--poses', '10', '--candidates', '10'), '--candidates'),
                 (('--poses', '10', '--end-candidates', '-1'), '--end-candidates'),
                 (('--poses', '10', '--end-candidates', '100001'), '--end-candidates'),
                 (('--poses', '10', '--min-z', 'nan'), '--min-z'),
                 (('--poses', '10', '--min-z', '1e300'), '--min-z'),
                 (('--poses', '10', '--effects', 'warp_drive'), 'warp_drive'),
                 (('--poses', '10', '--bogus'), '--bogus'),
                 (('--poses', '10', 'stray'), 'stray')]
        for existing in (None, 'q1,q2,q3\n1,2,3\n'):
            for args, word in cases:
                if existing is None:
                    if os.path.exists(self.out):
                        os.remove(self.out)
                else:
                    self.write('calibrated.json', existing)
                r = self.plan(*args)
                self.assert_bad_input(r, word)
                self.assert_out_untouched(existing)
        r = self.run_dhcal('plan', '--model', self.write('m.json', '{"joints": ['),
                           '--poses', '5', '--out', self.out)
        self.assert_bad_input(r, 'm.json')
        r = self.run_dhcal('plan', '--poses', '5', '--out', self.out)
        self.assert_bad_input(r, '--model')

    def test_plan_writes_the_poses_it_reports(self):
        model = json.loads(GOOD_MODEL)
        r = self.plan('--poses', '12', '--candidates', '150', '--seed', '3', '--json')
        self.assertEqual(r.returncode, 0, r.stderr)
        rep = json.loads(r.stdout)
        for key in ('poses', 'candidates', 'end_candidates', 'measured', 'parameters',
                    'identifiable', 'left_out', 'o1', 'rank', 'o1_random', 'rank_random',
                    'variance', 'variance_random', 'variance_floor', 'variance_weighted',
                    'weighting_iterations', 'exchanges', 'out'):
            self.assertIn(key, rep)
        self.assertEqual((rep['poses'], rep['candidates'], rep['end_candidates']),
                         (12, 150, 150))
        self.assertGreater(rep['o1'], rep['o1_random'])
        self.assertLess(rep['variance'], rep['variance_random'])
        with open(self.out) as f:
            rows = [l.strip() for l in f if l.strip() and not l.startswith('#')]
        self.assertEqual(rows[0], 'q1,q2,q3')
        poses = [tuple(float(v) for v in l.split(',')) for l in rows[1:]]
        self.assertEqual(len(poses), 12)
        self.assertEqual(len(set(poses)), 12)
        for q in poses:
            for j, v in enumerate(q):
                lo = model['joints'][j].get('min_deg', -180.0)
                hi = model['joints'][j].get('max_deg', 180.0)
                self.assertTrue(lo <= v <= hi, (j, v, lo, hi))
        # the same arguments give the same plan
        with open(self.out) as f:
            first = f.read()
        self.assertEqual(self.plan('--poses', '12', '--candidates', '150', '--seed', '3')
                         .returncode, 0)
        with open(self.out) as f:
            self.assertEqual(f.read(), first)
        # without end candidates: the same random plan (the first 150 do not depend on
        # them), a plan chosen from fewer poses
        r = self.plan('--poses', '12', '--candidates', '150', '--seed', '3',
                      '--end-candidates', '0', '--json')
        self.assertEqual(r.returncode, 0, r.stderr)
        alone = json.loads(r.stdout)
        self.assertEqual(alone['end_candidates'], 0)
        self.assertEqual(alone['variance_random'], rep['variance_random'])
        self.assertGreaterEqual(alone['variance_floor'], rep['variance_floor'] * (1 - 1e-2))

    def test_help_on_every_command(self):
        for cmd in ('compare', 'fit', 'diagnose', 'plot', 'plan'):
            r = self.run_dhcal(cmd, '--help')
            self.assertEqual(r.returncode, 0)
            self.assertIn('usage: dhcal ' + cmd, r.stdout)

    # ---- a computation that fails: exit 1, --out untouched
    def test_under_determined_data_fail_with_exit_1(self):
        rows = GOOD_CSV.splitlines()
        header = [l for l in rows if not l.startswith('#')][0]
        few = self.write('few.csv', header + '\n' + '\n'.join(
            [l for l in rows if not l.startswith('#')][1:4]) + '\n')
        self.write('calibrated.json', 'previous calibration\n')
        r = self.fit(None, few)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn('under-determine', r.stderr)
        self.assert_out_untouched('previous calibration\n')

    def test_cross_validation_that_cannot_run_fails_with_exit_1(self):
        # Four rows (12 equations) determine the base model; leave-one-out leaves three,
        # which do not (test_under_determined_data_fail_with_exit_1): every fold fails.
        rows = [l for l in GOOD_CSV.splitlines() if not l.startswith('#')]
        four = self.write('four.csv', '\n'.join(rows[:5]) + '\n')
        self.write('calibrated.json', 'previous calibration\n')
        plain = self.fit(None, four, '--json')
        self.assertEqual(plain.returncode, 0, plain.stderr)
        self.write('calibrated.json', 'previous calibration\n')
        for cmd in ('fit', 'diagnose'):
            # diagnose starts as refine does: with so few rows it would choose the geometry
            # level by cross-validation; --geometry full asks for the level that cannot
            args = ['--out', self.out] if cmd == 'fit' else ['--geometry', 'full']
            r = self.run_dhcal(cmd, '--model', self.model, '--data', four, '--cv', '--json',
                               *args)
            self.assertEqual(r.returncode, 1, '%s --cv: %s' % (cmd, r.stderr))
            self.assertIn('cross-validation', r.stderr)
            self.assertEqual(r.stdout, '', '%s --cv printed a report without cv_rms_mm' % cmd)
            self.assert_out_untouched('previous calibration\n')

    # ---- success: --out replaced atomically and loads again
    def test_successful_fit_writes_a_model_that_loads_again(self):
        self.write('calibrated.json', 'previous calibration\n')
        r = self.fit(None, None, '--effects', 'joint_compliance:2', '--json')
        self.assertEqual(r.returncode, 0, r.stderr)
        fit = json.loads(r.stdout)
        again = self.run_dhcal('compare', '--model', self.out, '--data', self.data, '--json')
        self.assertEqual(again.returncode, 0, again.stderr)
        # The saved model (effects included) reproduces the fit's residual.
        self.assertAlmostEqual(json.loads(again.stdout)['rms_mm'], fit['rms_mm'], places=6)
        with open(self.out) as f:
            saved = json.load(f)
        self.assertIn('joint_compliance:2', saved['effects'])

    def test_base_rotation_parameters_report_the_rotation_fitted(self):
        # A nominal base turned by a few degrees: the fit turns it back. base_rx..rz report
        # that turn, the rotation vector of R_out R_in^T, computed here from the two files.
        model = json.loads(GOOD_MODEL)
        model['base'] = {'xyz_mm': [2.0, -1.0, 3.0], 'rpy_deg': [1.5, -2.0, 3.0]}
        turned = self.write('turned.json', json.dumps(model))
        r = self.fit(turned, None, '--effects', 'base_frame', '--json')
        self.assertEqual(r.returncode, 0, r.stderr)
        reported = {p['name']: p['value'] for p in json.loads(r.stdout)['parameters']}
        with open(self.out) as f:
            fitted = json.load(f)['base']['rpy_deg']
        r_in, r_out = rot_from_rpy_deg(model['base']['rpy_deg']), rot_from_rpy_deg(fitted)
        turn = [[sum(r_out[i][m] * r_in[j][m] for m in range(3)) for j in range(3)]
                for i in range(3)]
        expected = rotation_vector_deg(turn)
        self.assertGreater(math.sqrt(sum(v * v for v in expected)), 3.0)  # not a null test
        checked = 0
        for axis, name in enumerate(('base_rx', 'base_ry', 'base_rz')):
            if name in reported:  # base_rz trades off with theta1: one of them is held
                self.assertAlmostEqual(reported[name], expected[axis], delta=1e-9, msg=name)
                checked += 1
        self.assertGreaterEqual(checked, 2)

    def test_text_report_gives_each_parameter_its_unit(self):
        # docs/cli.md, 1.4: drift_scale in 1/s, drift_offset in mm/s, compliance in deg/mm.
        r = self.run_dhcal('fit', '--model', self.model, '--data', self.data, '--effects',
                           'joint_compliance:2,drift_scale,drift_offset')
        self.assertEqual(r.returncode, 0, r.stderr)
        units = {}
        for line in r.stdout.splitlines():
            f = line.split()
            if len(f) >= 3 and f[0] in ('theta1', 'a2', 'drift_scale', 'drift_offset_x',
                                        'compliance2_2'):
                units[f[0]] = f[3] if len(f) > 3 else ''
        self.assertEqual(units, {'theta1': 'deg', 'a2': 'mm', 'drift_scale': '1/s',
                                 'drift_offset_x': 'mm/s', 'compliance2_2': 'deg/mm'})

    def test_json_keys_follow_the_design(self):
        r = self.run_dhcal('diagnose', '--model', self.model, '--data', self.data, '--json')
        self.assertEqual(r.returncode, 0, r.stderr)
        d = json.loads(r.stdout)
        for key in ('rms_mm', 'max_mm', 'iterations', 'converged', 'parameters',
                    'unidentifiable', 'outliers', 'candidates'):
            self.assertIn(key, d)
        c = d['candidates'][0]
        for key in ('effect', 'joint', 'explained', 'significant', 'params'):
            self.assertIn(key, c)
        self.assertEqual((c['effect'], c['joint'], c['significant']),
                         ('joint_compliance', 2, True))
        self.assertTrue(0.0 <= c['explained'] <= 1.0)
        p = d['parameters'][0]
        self.assertEqual(sorted(p), ['name', 'std', 'value'])


if __name__ == '__main__':
    if '--dhcal' not in sys.argv:
        sys.exit('usage: test_cli.py --dhcal PATH')
    i = sys.argv.index('--dhcal')
    DHCAL = os.path.abspath(sys.argv[i + 1])
    del sys.argv[i:i + 2]
    if '--wrapper' in sys.argv:
        i = sys.argv.index('--wrapper')
        WRAPPER = shlex.split(sys.argv[i + 1])
        del sys.argv[i:i + 2]
    unittest.main(verbosity=1)
