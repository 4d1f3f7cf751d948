#!/usr/bin/env python3
"""Known effects injected into real measurements (issue #26, first acceptance bullet).

The laser-tracker sets of --realdata DIR (by default ../shared/realdata beside the repository;
read there, never copied into it) carry the arms' own, unknown errors. To each set's measured
points this test adds the tool displacement of a known joint-angle effect,

    xyz' = xyz + FK(q + dq(q)) - FK(q)        (the nominal model, the test's own kinematics)

for the training and the held-out rows, and runs dhcal on the result as a user would:

    dhcal diagnose --model M --data TRAIN --effects base_frame,tool_offset --json
    dhcal refine   --model M --data TRAIN --effects base_frame,tool_offset --heldout HELD --json

Each case passes when
  - diagnose names the injected effect (`named`, else its first significant candidate), or
    names a candidate whose look-alikes (`look_alikes`, else the older `lookalike`) hold it;
  - refine's first step adds the injected effect or a look-alike of it (dhcal's own say-so:
    the test never decides which effects look alike);
  - refine's held-out RMS and mean end within 10 % of refine on the uninjected data (no
    worse than 1.10 x; run once per arm).
The test passes at the issue's bar: at least 6 cases pass, on 3 arms, and the passing cases
cover joint_scale, joint_harmonic (order 1), joint_harmonic2 and joint_compliance; every case
is run and printed with its numbers, a case that misses included.

Independent kinematics: the forward kinematics below is the model file's formula
(docs/formats.md 1: p = base * A_1 ... A_N * tool_mm, A_i = Rz(q_i + theta_i) Tz(d_i)
Tx(a_i) Rx(alpha_i) Ry(beta_i), base R = Rz(yaw) Ry(pitch) Rx(roll)) written again, not the
library's. It is checked first: every row's nominal error must equal `dhcal compare --json`'s
error_mm within 1e-6 mm, and each injected field (written into a model file's `effects`)
must equal dhcal's own prediction of that effect within 1e-6 mm (docs/effects.md 1: the
effects' formulas, compliance's gravity moments tau_ij = z_{i-1} . ((o_j - o_{i-1}) x g), g the
model's `gravity`, default [0, 0, -1]).

Size: what a geometric fit cannot absorb is at least 1.5 x the arm's own residual after
geometry (`dhcal fit --effects base_frame,tool_offset` on the uninjected training rows). The
absorbable part is the linear projection of the injected field onto the columns of the fit
dhcal runs: a central finite-difference Jacobian of this file's forward kinematics with
respect to every link parameter (theta, d, a, alpha; beta in place of d on joints with a
nominally parallel next axis, as dhcal's Hayati rule), the base frame's 6 (translation and a
small rotation about world axes through the base origin) and the tool's 3. The amplitude is
scaled until the RMS of the part left is >= 1.5 x that residual (the injection's own
nonlinearity included), and no further.

Shapes (fixed before any run, the same on every arm): joint_scale dq = s q; joint_harmonic
and joint_harmonic2 with A = B (phase 45 deg), amplitude sqrt(A^2 + B^2); joint_compliance
with every c_ij (j >= i) equal: a unit weight at each frame origin from joint i to the flange.
Cases are chosen by the physics: joints whose range in the training rows spans enough of a
turn for the shape to be told from a joint offset (scale on a joint spanning 80-400 deg,
order-1 harmonics on joints spanning 240 deg or more, order 2 on joints spanning about 150 deg
or more, so 2q spans most of a turn), compliance about a pitch joint that carries the arm's
weight. The last joint, whose rotation barely moves the tool point, is not used. On UR10 D the
ISO-cube poses keep the tool's orientation, so q5 = +-q1 on most rows: joint 5's effects look
like joint 1's there and theta5, d5 are not identified, which lets the geometric start absorb
an injected wrist or elbow effect into a wrist that turns by tens of degrees; the UR10's
order-1 harmonic and compliance cases use series B (even rows fitted, odd rows held out),
whose poses turn the wrist independently.

Positions only: the test writes its copies (q1..qN, x, y, z) to --scratch (the build tree),
never to the repository. Skips with the reason, exit 77, when the data folder is absent.

Usage: test_injected.py --dhcal PATH [--realdata DIR] [--scratch DIR]
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from operator import mul

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'acceptance'))
from checks import Checks  # noqa: E402  (the one tally of the test scripts)

SKIP = 77
START = 'base_frame,tool_offset'
RATIO = 1.5          # the part a geometric fit cannot absorb, x the arm's own residual
HELDOUT_TOL = 0.10   # held-out RMS and mean within 10 % of refine on the uninjected data
FK_TOL_MM = 1e-6     # own kinematics against dhcal compare
MIN_CASES = 6        # the bar: at least 6 cases over 3 arms
MIN_ARMS = 3
DEG = math.pi / 180.0

# (arm folder, effect, joint): see the docstring for why these joints
CASES = [
    ('ur5-jacobi', 'joint_scale', 2),        # q2 spans 80 deg (the issue's own example)
    ('ur5-jacobi', 'joint_harmonic2', 4),    # q4 spans 149 deg: 2 q4 most of a turn
    ('ur5-jacobi', 'joint_compliance', 2),   # shoulder pitch, carries the arm
    ('wam-jacobi', 'joint_harmonic', 1),     # q1 spans 241 deg, lever = the horizontal reach
    ('wam-jacobi', 'joint_compliance', 2),   # shoulder pitch, q2 spans 178 deg
    ('ur10-ipa-d', 'joint_scale', 1),        # q1 spans 404 deg
    ('ur10-ipa-d', 'joint_harmonic2', 3),    # q3 spans 301 deg
    ('ur10-ipa-b', 'joint_harmonic', 3),     # q3 spans 250 deg
    ('ur10-ipa-b', 'joint_compliance', 3),   # elbow pitch, carries the forearm and wrist
]


# ---------------------------------------------------------------- kinematics (own, pure Python)
# 3x3 matrices are row-major 9-tuples, vectors 3-tuples.

def mat_mul(a, b):
    return (a[0] * b[0] + a[1] * b[3] + a[2] * b[6], a[0] * b[1] + a[1] * b[4] + a[2] * b[7],
            a[0] * b[2] + a[1] * b[5] + a[2] * b[8],
            a[3] * b[0] + a[4] * b[3] + a[5] * b[6], a[3] * b[1] + a[4] * b[4] + a[5] * b[7],
            a[3] * b[2] + a[4] * b[5] + a[5] * b[8],
            a[6] * b[0] + a[7] * b[3] + a[8] * b[6], a[6] * b[1] + a[7] * b[4] + a[8] * b[7],
            a[6] * b[2] + a[7] * b[5] + a[8] * b[8])


def mat_vec(m, v):
    return (m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
            m[6] * v[0] + m[7] * v[1] + m[8] * v[2])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def rot_x(t):
    c, s = math.cos(t), math.sin(t)
    return (1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)


def rot_y(t):
    c, s = math.cos(t), math.sin(t)
    return (c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)


def rot_z(t):
    c, s = math.cos(t), math.sin(t)
    return (c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)


def rodrigues(axis, t):
    """Rotation by t about a world axis (unit vector)."""
    x, y, z = axis
    c, s = math.cos(t), math.sin(t)
    v = 1.0 - c
    return (c + x * x * v, x * y * v - z * s, x * z * v + y * s,
            y * x * v + z * s, c + y * y * v, y * z * v - x * s,
            z * x * v - y * s, z * y * v + x * s, c + z * z * v)


class Arm:
    """The model file, read as docs/formats.md 2 describes it (mm and radians in memory)."""

    def __init__(self, path):
        with open(path) as f:
            self.doc = json.load(f)
        m = self.doc
        self.joints = []
        for j in m['joints']:
            self.joints.append({'theta': j.get('theta_offset_deg', 0.0) * DEG, 'd': j['d_mm'],
                                'a': j['a_mm'], 'alpha': j['alpha_deg'] * DEG,
                                'beta': j.get('beta_deg', 0.0) * DEG})
        self.n = len(self.joints)
        self.tool = tuple(m.get('tool_mm', [0.0, 0.0, 0.0]))
        base = m.get('base', {})
        self.base_p = tuple(base.get('xyz_mm', [0.0, 0.0, 0.0]))
        roll, pitch, yaw = (v * DEG for v in base.get('rpy_deg', [0.0, 0.0, 0.0]))
        self.base_r = mat_mul(mat_mul(rot_z(yaw), rot_y(pitch)), rot_x(roll))
        g = m.get('gravity', [0.0, 0.0, -1.0])
        ng = math.sqrt(sum(v * v for v in g))
        self.gravity = tuple(v / ng for v in g)
        if 'effects' in m:
            raise SystemExit(f'{path}: a nominal model with effects is not expected here')
        # dhcal's Hayati rule: a joint that is not the last with a nominally parallel twist
        # has beta fitted in place of d (docs/formats.md 1)
        self.hayati = [i < self.n - 1 and abs(math.sin(j['alpha'])) < 1e-3
                       for i, j in enumerate(self.joints)]

    def local_point(self, i, q, r, dtheta=0.0, dd=0.0, da=0.0, dalpha=0.0, dbeta=0.0):
        """A_i(q) applied to the point r of frame i: the point in frame i-1 (0-based i)."""
        j = self.joints[i]
        x, y, z = r
        b = j['beta'] + dbeta
        if b != 0.0:
            cb, sb = math.cos(b), math.sin(b)
            x, z = cb * x + sb * z, -sb * x + cb * z
        al = j['alpha'] + dalpha
        ca, sa = math.cos(al), math.sin(al)
        y, z = ca * y - sa * z, sa * y + ca * z
        x += j['a'] + da
        z += j['d'] + dd
        t = q + j['theta'] + dtheta
        ct, st = math.cos(t), math.sin(t)
        return (ct * x - st * y, st * x + ct * y, z)

    def frames(self, q):
        """World rotation and origin of frames 0..N (frame 0: the base) at joint angles q (rad)."""
        rs = [self.base_r]
        os_ = [self.base_p]
        for i, j in enumerate(self.joints):
            t = q[i] + j['theta']
            ct, st = math.cos(t), math.sin(t)
            r_prev = rs[-1]
            os_.append(add(os_[-1], mat_vec(r_prev, (j['a'] * ct, j['a'] * st, j['d']))))
            loc = mat_mul(rot_z(t), rot_x(j['alpha']))
            if j['beta'] != 0.0:
                loc = mat_mul(loc, rot_y(j['beta']))
            rs.append(mat_mul(r_prev, loc))
        return rs, os_

    def tool_point(self, q):
        rs, os_ = self.frames(q)
        return add(os_[-1], mat_vec(rs[-1], self.tool))

    def moments(self, q, i):
        """tau_ij for j = i..N (1-based i): gravity moment about axis i of a unit weight at the
        origin of frame j, mm (docs/effects.md 1)."""
        rs, os_ = self.frames(q)
        r = rs[i - 1]
        z = (r[2], r[5], r[8])
        out = []
        for j in range(i, self.n + 1):
            m = cross(sub(os_[j], os_[i - 1]), self.gravity)
            out.append(z[0] * m[0] + z[1] * m[1] + z[2] * m[2])
        return out

    def geometric_columns(self, qs, h=1e-6):
        """Central finite-difference Jacobian of the tool point over the rows qs with respect
        to the fit dhcal runs with --effects base_frame,tool_offset at --geometry full: every
        link parameter, the base frame's 6, the tool's 3. Columns of length 3 * rows."""
        names = []
        for i in range(self.n):
            names += [f'theta{i + 1}', f'beta{i + 1}' if self.hayati[i] else f'd{i + 1}',
                      f'a{i + 1}', f'alpha{i + 1}']
        names += ['base_x', 'base_y', 'base_z', 'base_rx', 'base_ry', 'base_rz',
                  'tool_x', 'tool_y', 'tool_z']
        cols = [[] for _ in names]
        e3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
        for q in qs:
            rs, os_ = self.frames(q)
            # suffix points: the tool point in frame i, i = N..0
            suffix = [None] * (self.n + 1)
            suffix[self.n] = self.tool
            for i in range(self.n - 1, -1, -1):
                suffix[i] = self.local_point(i, q[i], suffix[i + 1])
            p = add(self.base_p, mat_vec(self.base_r, suffix[0]))
            k = 0
            for i in range(self.n):
                keys = ['dtheta', 'dbeta' if self.hayati[i] else 'dd', 'da', 'dalpha']
                for key in keys:
                    plus = self.local_point(i, q[i], suffix[i + 1], **{key: h})
                    minus = self.local_point(i, q[i], suffix[i + 1], **{key: -h})
                    col = mat_vec(rs[i], sub(plus, minus))
                    cols[k].extend(v / (2.0 * h) for v in col)
                    k += 1
            for e in e3:                       # base translation
                plus = add(p, tuple(h * v for v in e))
                minus = add(p, tuple(-h * v for v in e))
                cols[k].extend(v / (2.0 * h) for v in sub(plus, minus))
                k += 1
            lever = sub(p, self.base_p)        # base rotation about world axes, base origin
            for e in e3:
                plus = mat_vec(rodrigues(e, h), lever)
                minus = mat_vec(rodrigues(e, -h), lever)
                cols[k].extend(v / (2.0 * h) for v in sub(plus, minus))
                k += 1
            for e in e3:                       # tool point in the last frame
                plus = add(os_[-1], mat_vec(rs[-1], add(self.tool, tuple(h * v for v in e))))
                minus = add(os_[-1], mat_vec(rs[-1], sub(self.tool, tuple(h * v for v in e))))
                cols[k].extend(v / (2.0 * h) for v in sub(plus, minus))
                k += 1
        return names, cols


def dot(a, b):
    return sum(map(mul, a, b))


class Projector:
    """Orthonormal basis of the geometric columns (modified Gram-Schmidt, twice), dropping the
    columns the others already span (d1 against base_z and the like)."""

    def __init__(self, cols, tol=1e-7):
        self.basis = []
        self.dropped = 0
        for c in cols:
            n0 = math.sqrt(dot(c, c))
            if n0 == 0.0:
                self.dropped += 1
                continue
            v = [x / n0 for x in c]
            for _ in range(2):
                for b in self.basis:
                    k = dot(b, v)
                    v = [x - k * y for x, y in zip(v, b)]
            nv = math.sqrt(dot(v, v))
            if nv < tol:
                self.dropped += 1
                continue
            self.basis.append([x / nv for x in v])

    def split(self, field):
        """(absorbed, left): the field's projection onto the columns and the rest."""
        left = list(field)
        for _ in range(2):
            for b in self.basis:
                k = dot(b, left)
                left = [x - k * y for x, y in zip(left, b)]
        absorbed = [x - y for x, y in zip(field, left)]
        return absorbed, left


def rms_rows(flat):
    """RMS over rows of the 3-D norm (dhcal's rms_mm)."""
    return math.sqrt(dot(flat, flat) / (len(flat) // 3))


# ---------------------------------------------------------------- effects
def effect_values(effect, amp, n, joint):
    """The model file's values (display units, docs/formats.md 2.5) of the injected effect at
    amplitude amp: scale unitless, harmonic amplitude in deg at phase 45 deg, compliance deg/mm
    for every c_ij."""
    if effect == 'joint_scale':
        return [amp]
    if effect in ('joint_harmonic', 'joint_harmonic2'):
        return [amp / math.sqrt(2.0), amp / math.sqrt(2.0)]
    if effect == 'joint_compliance':
        return [amp] * (n - joint + 1)
    raise ValueError(effect)


def joint_error(arm, effect, values, joint, q):
    """dq of the joint (rad) at q (rad), docs/effects.md 1."""
    qi = q[joint - 1]
    if effect == 'joint_scale':
        return values[0] * qi
    if effect == 'joint_harmonic':
        return (values[0] * math.sin(qi) + values[1] * math.cos(qi)) * DEG
    if effect == 'joint_harmonic2':
        return (values[0] * math.sin(2.0 * qi) + values[1] * math.cos(2.0 * qi)) * DEG
    if effect == 'joint_compliance':
        return sum(c * t for c, t in zip(values, arm.moments(q, joint))) * DEG
    raise ValueError(effect)


def displacement(arm, effect, values, joint, qs):
    """FK(q + dq(q)) - FK(q) for every row, flattened."""
    out = []
    for q in qs:
        dq = joint_error(arm, effect, values, joint, q)
        q2 = list(q)
        q2[joint - 1] += dq
        out.extend(sub(arm.tool_point(q2), arm.tool_point(q)))
    return out


def amplitude_text(effect, amp):
    if effect == 'joint_scale':
        return f'{amp * 100:.4f} %'
    if effect.startswith('joint_harmonic'):
        return f'{amp:.4f} deg'
    return f'{amp:.3e} deg/mm'


UNIT_AMP = {'joint_scale': 1e-3, 'joint_harmonic': 0.01, 'joint_harmonic2': 0.01,
            'joint_compliance': 1e-5}


# ---------------------------------------------------------------- data files
class Rows:
    """A measurement CSV's comment lines, angle strings (degrees) and measured points."""

    def __init__(self, path, parity=None):
        with open(path) as f:
            lines = f.read().splitlines()
        head_i = next(i for i, l in enumerate(lines) if l and not l.startswith('#'))
        self.comments = [l for l in lines[:head_i] if l.startswith('#')]
        header = lines[head_i].split(',')
        self.qcols = [i for i, c in enumerate(header) if c.startswith('q') and c[1:].isdigit()]
        self.qnames = [header[i] for i in self.qcols]
        xyz = [header.index(c) for c in ('x', 'y', 'z')]
        self.q_text, self.xyz_text = [], []
        data = [l for l in lines[head_i + 1:] if l and not l.startswith('#')]
        for k, l in enumerate(data):
            if parity is not None and k % 2 != parity:
                continue
            cells = l.split(',')
            self.q_text.append([cells[i] for i in self.qcols])
            self.xyz_text.append([cells[i] for i in xyz])
        self.q = [[float(v) * DEG for v in r] for r in self.q_text]
        self.xyz = [tuple(float(v) for v in r) for r in self.xyz_text]

    def write(self, path, note, shift=None):
        """Positions only (q1..qN, x, y, z); with shift (flattened) added to the points."""
        with open(path, 'w') as f:
            for l in self.comments:
                f.write(l + '\n')
            f.write(f'# {note}\n')
            f.write(','.join(self.qnames + ['x', 'y', 'z']) + '\n')
            for k, (qt, xt) in enumerate(zip(self.q_text, self.xyz_text)):
                if shift is None:
                    pts = xt
                else:
                    pts = ['%.9f' % (self.xyz[k][c] + shift[3 * k + c]) for c in range(3)]
                f.write(','.join(qt + pts) + '\n')


# ---------------------------------------------------------------- dhcal
def run_json(dhcal, args):
    r = subprocess.run([dhcal] + args, capture_output=True, text=True, timeout=600)
    try:
        out = json.loads(r.stdout) if r.stdout.strip() else None
    except json.JSONDecodeError:
        out = None
    return r, out


def run_pair(dhcal, args_a, args_b):
    """Two dhcal runs side by side (2 cores): [(returncode, stderr, json), ...]."""
    procs = [subprocess.Popen([dhcal] + a, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) for a in (args_a, args_b)]
    res = []
    for p in procs:
        so, se = p.communicate(timeout=600)
        try:
            out = json.loads(so) if so.strip() else None
        except json.JSONDecodeError:
            out = None
        res.append((p.returncode, se.strip(), out))
    return res


def label(c):
    return c['effect'] if c.get('joint') is None else f'{c["effect"]}:{c["joint"]}'


def diagnosis(out):
    """(named label or None, {label: set of look-alike labels}, whether the new keys exist)."""
    cands = out.get('candidates', [])
    looks = {}
    for c in cands:
        if 'look_alikes' in c:
            looks[label(c)] = set(c['look_alikes'] or [])
        elif c.get('lookalike'):
            looks[label(c)] = {c['lookalike']}
        else:
            looks[label(c)] = set()
    if 'named' in out:
        named = out['named']
    else:
        named = next((label(c) for c in cands if c.get('significant')), None)
    new_keys = 'named' in out and any('look_alikes' in c for c in cands)
    return named, looks, new_keys


def look_alike(looks, a, b):
    """a is b, or dhcal lists either as a look-alike of the other."""
    return a == b or b in looks.get(a, set()) or a in looks.get(b, set())


# ---------------------------------------------------------------- the test
def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--dhcal', required=True)
    ap.add_argument('--realdata', default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), '..', '..', '..', 'shared', 'realdata'))
    ap.add_argument('--scratch', default=None)
    a = ap.parse_args()
    t_start = time.monotonic()
    rd = os.path.abspath(a.realdata)
    if not os.path.isdir(rd):
        print(f'SKIP: no real data at {rd} (the shared folder beside the repository, '
              'DHCAL_REALDATA_DIR); this test reads it from there and never copies it')
        return SKIP
    arms = sorted({c[0] for c in CASES})
    missing = [d for d in arms if not os.path.isfile(os.path.join(rd, d, 'model.json'))]
    if missing:
        print(f'SKIP: {rd} lacks {", ".join(missing)}')
        return SKIP
    c = Checks()
    scratch = a.scratch or tempfile.mkdtemp(prefix='dhcal-injected-')
    os.makedirs(scratch, exist_ok=True)
    table = []

    for arm_name in [d for d in dict.fromkeys(x[0] for x in CASES)]:
        d = os.path.join(rd, arm_name)
        model_path = os.path.join(d, 'model.json')
        arm = Arm(model_path)
        if os.path.isfile(os.path.join(d, 'heldout.csv')):
            train = Rows(os.path.join(d, 'data.csv'))
            held = Rows(os.path.join(d, 'heldout.csv'))
            split = 'data.csv / heldout.csv'
        else:
            train = Rows(os.path.join(d, 'data.csv'), parity=0)
            held = Rows(os.path.join(d, 'data.csv'), parity=1)
            split = 'data.csv even rows / odd rows'
        print(f'==== {arm_name}: {arm.n} joints, {len(train.q)} training rows, '
              f'{len(held.q)} held out ({split})', flush=True)
        train_path = os.path.join(scratch, f'{arm_name}-train.csv')
        held_path = os.path.join(scratch, f'{arm_name}-held.csv')
        train.write(train_path, 'positions only, as measured (test_injected.py)')
        held.write(held_path, 'positions only, as measured (test_injected.py)')

        # ---- own kinematics against dhcal compare, before anything relies on it
        for rows, path, what in ((train, train_path, 'training'), (held, held_path, 'held-out')):
            r, out = run_json(a.dhcal, ['compare', '--model', model_path, '--data', path,
                                        '--json'])
            if r.returncode != 0 or out is None:
                c.check(f'{arm_name}: dhcal compare on the {what} rows', False,
                        f'exit {r.returncode} {r.stderr.strip()}')
                print('FAIL: cannot verify the test\'s kinematics; stopping', flush=True)
                return 1
            own = [math.dist(arm.tool_point(q), p) for q, p in zip(rows.q, rows.xyz)]
            theirs = [x['error_mm'] for x in out['rows']]
            worst = max(abs(x - y) for x, y in zip(own, theirs)) if len(own) == len(theirs) \
                else float('inf')
            ok = len(own) == len(theirs) and worst <= FK_TOL_MM
            c.check(f'{arm_name}: own forward kinematics = dhcal compare on the {what} rows '
                    f'(per-row error within {FK_TOL_MM:g} mm)', ok,
                    f'{len(own)} rows, largest difference {worst:.2e} mm')
            if not ok:
                print('FAIL: the test\'s kinematics disagree with dhcal\'s; every size below '
                      'would be wrong; stopping', flush=True)
                return 1

        # ---- the arm's own residual after geometry, and refine on the uninjected data
        r, fit = run_json(a.dhcal, ['fit', '--model', model_path, '--data', train_path,
                                    '--effects', START, '--json'])
        c.check(f'{arm_name}: fit of the uninjected rows exits 0', r.returncode == 0 and
                fit is not None, f'exit {r.returncode} {r.stderr.strip()}')
        if fit is None:
            continue
        own_rms = fit['rms_mm']
        t0 = time.monotonic()
        r, base_ref = run_json(a.dhcal, ['refine', '--model', model_path, '--data', train_path,
                                         '--effects', START, '--heldout', held_path, '--json'])
        t_ref = time.monotonic() - t0
        c.check(f'{arm_name}: refine of the uninjected rows exits 0', r.returncode == 0 and
                base_ref is not None, f'exit {r.returncode} {r.stderr.strip()}')
        if base_ref is None:
            continue
        base_steps = ' -> '.join(s['added'] or 'start' for s in base_ref['steps'])
        print(f'      own residual after geometry {own_rms:.4f} mm RMS; uninjected refine '
              f'({t_ref:.1f} s): {base_steps}; held-out RMS {base_ref["heldout_rms_mm"]:.4f}, '
              f'mean {base_ref["heldout_mean_mm"]:.4f} mm', flush=True)

        # ---- what the geometric fit spans, over the training rows
        t0 = time.monotonic()
        names, cols = arm.geometric_columns(train.q)
        proj = Projector(cols)
        print(f'      geometric columns: {len(names)}, {len(proj.basis)} independent '
              f'({time.monotonic() - t0:.1f} s)', flush=True)

        for case_arm, effect, joint in CASES:
            if case_arm != arm_name:
                continue
            name = f'{effect}:{joint}'
            tag = f'{arm_name} {name}'
            # size: linear first guess, then the injection's own nonlinearity
            amp = UNIT_AMP[effect]
            for _ in range(8):
                vals = effect_values(effect, amp, arm.n, joint)
                field = displacement(arm, effect, vals, joint, train.q)
                absorbed, left = proj.split(field)
                ratio = rms_rows(left) / own_rms
                if RATIO <= ratio <= RATIO * 1.005:
                    break
                amp *= RATIO * 1.001 / ratio
            absorbed_rms, left_rms, total_rms = rms_rows(absorbed), rms_rows(left), \
                rms_rows(field)
            print(f'---- {tag}: amplitude {amplitude_text(effect, amp)}; at the tool RMS '
                  f'{total_rms:.4f} mm, absorbed by geometry {absorbed_rms:.4f}, left '
                  f'{left_rms:.4f} mm = {ratio:.3f} x own {own_rms:.4f} mm', flush=True)
            c.check(f'{tag}: left after geometry >= {RATIO} x the arm\'s own residual',
                    ratio >= RATIO, f'{ratio:.3f}')

            # the injected field is dhcal's effect: its own prediction with these values
            emodel = dict(arm.doc)
            emodel['effects'] = {name: vals}
            emodel_path = os.path.join(scratch, f'{arm_name}-{effect}-{joint}-model.json')
            with open(emodel_path, 'w') as f:
                json.dump(emodel, f, indent=1)
            r, out = run_json(a.dhcal, ['compare', '--model', emodel_path, '--data', train_path,
                                        '--json'])
            if out is not None:
                own = [math.dist(add(arm.tool_point(q), field[3 * k:3 * k + 3]), p)
                       for k, (q, p) in enumerate(zip(train.q, train.xyz))]
                theirs = [x['error_mm'] for x in out['rows']]
                worst = max(abs(x - y) for x, y in zip(own, theirs))
                c.check(f'{tag}: the injected field is dhcal\'s {name} with these values '
                        f'(compare, within {FK_TOL_MM:g} mm)', worst <= FK_TOL_MM,
                        f'largest difference {worst:.2e} mm')
            else:
                c.check(f'{tag}: compare with the effect in the model', False,
                        f'exit {r.returncode} {r.stderr.strip()}')

            # inject into the measured points of the training and the held-out rows
            note = (f'test_injected.py: measured points + the displacement of {name} = '
                    f'{vals} (display units) on the nominal model')
            itrain = os.path.join(scratch, f'{arm_name}-{effect}-{joint}-train.csv')
            iheld = os.path.join(scratch, f'{arm_name}-{effect}-{joint}-held.csv')
            train.write(itrain, note, field)
            held.write(iheld, note, displacement(arm, effect, vals, joint, held.q))

            t0 = time.monotonic()
            (rc_d, se_d, diag), (rc_r, se_r, ref) = run_pair(
                a.dhcal,
                ['diagnose', '--model', model_path, '--data', itrain, '--effects', START,
                 '--json'],
                ['refine', '--model', model_path, '--data', itrain, '--effects', START,
                 '--heldout', iheld, '--json'])
            t_run = time.monotonic() - t0
            row = {'case': tag, 'amp': amplitude_text(effect, amp), 'ratio': ratio,
                   'named': '-', 'first': '-', 'hr': None, 'hm': None,
                   'br': base_ref['heldout_rms_mm'], 'bm': base_ref['heldout_mean_mm'],
                   'ok': {}, 'secs': t_run}
            ok = rc_d == 0 and diag is not None
            c.check(f'{tag}: diagnose exits 0', ok, f'exit {rc_d} {se_d}')
            row['ok']['diagnose exit'] = ok
            ok = rc_r == 0 and ref is not None
            c.check(f'{tag}: refine exits 0', ok, f'exit {rc_r} {se_r}')
            row['ok']['refine exit'] = ok
            looks = {}
            row['ok']['diagnose names'] = False
            if diag is not None:
                named, looks, new_keys = diagnosis(diag)
                if not new_keys:
                    print('      (this build has no `named`/`look_alikes` yet: read the first '
                          'significant candidate and `lookalike`)')
                cands = diag.get('candidates', [])
                def shown(k):
                    la = sorted(looks[label(k)])
                    return (label(k) + ('*' if k.get('significant') else '') +
                            (' ~' + '/'.join(la) if la else ''))
                top = ', '.join(shown(k) for k in cands[:4])
                print(f'      diagnose: named {named}; first candidates (* significant, '
                      f'~ look-alikes): {top}')
                # strictly as the issue words it: the injected effect, or one of the named
                # candidate's own look-alikes
                ok = named is not None and (named == name or name in looks.get(named, set()))
                why = f'named {named}'
                if named is not None and named != name:
                    why += f' (its look-alikes: {sorted(looks.get(named, set())) or "none"})'
                rank = next((k for k, x in enumerate(cands) if label(x) == name), None)
                if named != name:
                    why += f'; {name} ranked {rank + 1 if rank is not None else "absent"}'
                    if rank is not None:
                        why += f', log10 p {cands[rank].get("log10_p", float("nan")):.1f}'
                c.check(f'{tag}: diagnose names {name} or a look-alike of it', ok, why)
                row['named'] = named or 'none'
                row['ok']['diagnose names'] = ok
            for key in ('refine first', 'held-out RMS', 'held-out mean'):
                row['ok'][key] = False
            if ref is not None:
                steps = ref.get('steps', [])
                first = steps[1]['added'] if len(steps) > 1 else None
                rows_cv = [s_['cv_rows'] for s_ in steps if 'cv_rows' in s_]
                print(f'      refine ({t_run:.1f} s with diagnose): '
                      f'{" -> ".join(s_["added"] or "start" for s_ in steps)}; held-out RMS '
                      f'{ref["heldout_rms_mm"]:.4f}, mean {ref["heldout_mean_mm"]:.4f} mm'
                      f'{"; cv_rows " + str(rows_cv) if rows_cv else ""}; '
                      f'stopped: {ref.get("stopped", "?")}')
                ok = first is not None and look_alike(looks, first, name)
                c.check(f'{tag}: refine adds {name} (or a look-alike) first', ok,
                        f'first step {first}' if first else
                        f'nothing added ({ref.get("stopped", "?")})')
                row['first'] = first or 'none'
                row['ok']['refine first'] = ok
                for key, short, bkey in (('heldout_rms_mm', 'RMS', 'br'),
                                         ('heldout_mean_mm', 'mean', 'bm')):
                    v, b = ref[key], row[bkey]
                    ok = v <= b * (1.0 + HELDOUT_TOL)
                    c.check(f'{tag}: held-out {short} within {HELDOUT_TOL:.0%} of refine on the '
                            f'uninjected data', ok, f'{v:.4f} vs {b:.4f} mm ({v / b - 1.0:+.1%})')
                    row['ok'][f'held-out {short}'] = ok
                    row['hr' if short == 'RMS' else 'hm'] = v
            table.append(row)

    # ---- the table
    print()
    print(f'{"case":<34} {"amplitude":>16} {"left/own":>8}  {"diagnose names":<20} '
          f'{"refine first":<20} {"held-out RMS: uninj -> inj":>27} {"mean: uninj -> inj":>20}'
          f'  verdict')
    for row in table:
        hr = f'{row["br"]:.4f} -> {row["hr"]:.4f}' if row['hr'] is not None else '-'
        hm = f'{row["bm"]:.4f} -> {row["hm"]:.4f}' if row['hm'] is not None else '-'
        verdict = 'pass' if all(row['ok'].values()) else 'FAIL: ' + ', '.join(
            w for w, o in row['ok'].items() if not o)
        print(f'{row["case"]:<34} {row["amp"]:>16} {row["ratio"]:>8.3f}  {row["named"]:<20} '
              f'{row["first"]:<20} {hr:>27} {hm:>20}  {verdict}')
    passed = [row for row in table if all(row['ok'].values())]
    print(f'\n{len(passed)} of {len(table)} cases pass; {c.passed} checks passed, {c.failed} '
          f'failed; {time.monotonic() - t_start:.0f} s')
    # The bar: at least 6 cases over 3 arms, covering scale, harmonics of order 1
    # and 2, and compliance. Every case is run and printed; a case that misses is shown
    # above with its numbers. Checks outside the cases' criteria (the test's own
    # kinematics, the sizing) must all pass.
    case_failures = sum(1 for row in table for ok in row['ok'].values() if not ok)
    arms_ok = {row['case'].split('-')[0] for row in passed}  # ur10-ipa-b, -d: one arm
    kinds_ok = {row['case'].split()[1].split(':')[0] for row in passed}
    kinds = {'joint_scale', 'joint_harmonic', 'joint_harmonic2', 'joint_compliance'}
    bar = len(passed) >= MIN_CASES and len(arms_ok) >= MIN_ARMS and kinds <= kinds_ok
    print(f'bar: {len(passed)} cases pass (>= {MIN_CASES}) on {len(arms_ok)} arms '
          f'(>= {MIN_ARMS}), kinds {sorted(kinds_ok)} (all of {sorted(kinds)}): '
          f'{"met" if bar else "NOT met"}')
    return 0 if bar and c.failed == case_failures else 1


if __name__ == '__main__':
    sys.exit(main())
