#!/usr/bin/env python3
"""dhcal import-urdf and export-urdf against forward kinematics computed here, independently
of dhcal's code (docs/cli.md, 1.7 and 1.8; docs/formats.md, section 11).

Two computations written from the specifications, in plain Python:
  - urdf_fk: the URDF's kinematics from the URDF specification: for each joint from the base
    link to the tip link, T = T * origin(xyz, rpy = Rz(yaw) Ry(pitch) Rx(roll)) * Rot(axis, q);
  - model_fk: the model file's kinematics from docs/formats.md, section 1:
    p = base * A_1 ... A_N * tool_mm, A_i = Rz(q_i + theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i) Ry(beta_i).
Positions are also checked through the dhcal program itself (`dhcal compare --json`, the
library's forward kinematics), with measurement rows made by urdf_fk.

Cases (--dhcal): the paper's 3-DOF arm written by hand as a URDF (tests/urdf/paper_arm.urdf,
frames not DH-aligned, axes along -y), against its model file examples/models/paper-3dof.json
too; random chains (random origins and axes, fixed joints between, continuous joints, nearly
parallel axes tilted by less than the Hayati threshold); export -> re-import round trips; bad
input: exit 2, the file and line named, an existing --out left byte for byte as it was.

With --realdata DIR (the folder urdf/ and ur5-jacobi/ of ../shared/realdata, read there, never
copied): each robot's URDF against its reference table <robot>.fk.csv (independent numpy
reader, checked with Pinocchio), before and after a round trip; the UR5 against the UR5 model
file of ur5-jacobi (T_DH = Rz(180 deg) T_urdf, urdf/README.md). Skips (exit 77) with the
reason when the folder is absent.

Tolerances: 1e-6 mm on tool points, 1e-9 rad on orientations.

Usage: test_urdf.py --dhcal PATH --scratch DIR [--realdata DIR] [--wrapper 'CMD ARGS']
  --wrapper runs every import-urdf and export-urdf under CMD (e.g. valgrind with
  --error-exitcode=99): a wrapper that reports through its exit code fails the case's exit
  code assertion. `dhcal compare`, the check's instrument, runs unwrapped.
"""
import argparse
import json
import math
import os
import random
import re
import shlex
import subprocess
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'acceptance'))
from checks import Checks  # noqa: E402  (the one tally of the test scripts)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
PAPER_URDF = os.path.join(HERE, 'paper_arm.urdf')
PAPER_MODEL = os.path.join(ROOT, 'examples', 'models', 'paper-3dof.json')
SKIP = 77
TOL_MM = 1e-6
TOL_RAD = 1e-9

# ------------------------------------------------------------------ small rigid-body algebra


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def transpose(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def apply(r, v):
    return [sum(r[i][k] * v[k] for k in range(3)) for i in range(3)]


def rot_x(t):
    c, s = math.cos(t), math.sin(t)
    return [[1, 0, 0], [0, c, -s], [0, s, c]]


def rot_y(t):
    c, s = math.cos(t), math.sin(t)
    return [[c, 0, s], [0, 1, 0], [-s, 0, c]]


def rot_z(t):
    c, s = math.cos(t), math.sin(t)
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]]


def rot_rpy(roll, pitch, yaw):
    """URDF's fixed-axis roll-pitch-yaw and the model file's rpy alike: Rz Ry Rx."""
    return matmul(rot_z(yaw), matmul(rot_y(pitch), rot_x(roll)))


def rot_axis(axis, t):
    """Rodrigues: rotation by t about the unit vector axis."""
    x, y, z = axis
    c, s, v = math.cos(t), math.sin(t), 1.0 - math.cos(t)
    return [[c + x * x * v, x * y * v - z * s, x * z * v + y * s],
            [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
            [z * x * v - y * s, z * y * v + x * s, c + z * z * v]]


def rot_quat(w, x, y, z):
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def compose(f, g):
    """Frames (R, p): f * g."""
    return matmul(f[0], g[0]), [a + b for a, b in zip(apply(f[0], g[1]), f[1])]


def angle_between(r1, r2):
    """Angle of r1^T r2, accurate near 0: |r1 - r2|_F = 2 sqrt(2) sin(angle / 2)."""
    frob = math.sqrt(sum((r1[i][j] - r2[i][j]) ** 2 for i in range(3) for j in range(3)))
    return 2.0 * math.asin(min(1.0, frob / (2.0 * math.sqrt(2.0))))


def dist(a, b):
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)))


IDENTITY = ([[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.0, 0.0, 0.0])

# ------------------------------------------------------------------ the two kinematics


def floats(text, default):
    return [float(v) for v in text.split()] if text is not None else list(default)


def urdf_chain(path, base, tip):
    """The joints (ElementTree elements) from base to tip, base first."""
    robot = ET.parse(path).getroot()
    by_child = {j.find('child').get('link'): j for j in robot.findall('joint')}
    chain, link = [], tip
    while link != base:
        joint = by_child[link]
        chain.append(joint)
        link = joint.find('parent').get('link')
    return chain[::-1]


def urdf_fk(chain, q_rad, point_mm=(0.0, 0.0, 0.0)):
    """Tip link frame (rotation, origin in mm) and point_mm (tip frame) in the base link."""
    frame, k = IDENTITY, 0
    for joint in chain:
        origin = joint.find('origin')
        xyz = floats(origin.get('xyz') if origin is not None else None, (0, 0, 0))
        rpy = floats(origin.get('rpy') if origin is not None else None, (0, 0, 0))
        frame = compose(frame, (rot_rpy(*rpy), [1000.0 * v for v in xyz]))
        if joint.get('type') in ('revolute', 'continuous'):
            axis_el = joint.find('axis')
            axis = floats(axis_el.get('xyz') if axis_el is not None else None, (1, 0, 0))
            n = math.sqrt(sum(v * v for v in axis))
            frame = compose(frame, (rot_axis([v / n for v in axis], q_rad[k]), [0.0, 0.0, 0.0]))
            k += 1
    point = [a + b for a, b in zip(apply(frame[0], list(point_mm)), frame[1])]
    return frame[0], point


def model_fk(model, q_rad):
    """Frame N's rotation and the tool point in the world (docs/formats.md, section 1)."""
    base = model.get('base', {})
    rpy = [math.radians(v) for v in base.get('rpy_deg', [0, 0, 0])]
    frame = (rot_rpy(*rpy), list(base.get('xyz_mm', [0, 0, 0])))
    for j, q in zip(model['joints'], q_rad):
        theta = q + math.radians(j.get('theta_offset_deg', 0.0))
        alpha = math.radians(j['alpha_deg'])
        beta = math.radians(j.get('beta_deg', 0.0))
        frame = compose(frame, (rot_z(theta), [0.0, 0.0, 0.0]))
        frame = compose(frame, (matmul(rot_x(alpha), rot_y(beta)), [j['a_mm'], 0.0, j['d_mm']]))
    tool = model.get('tool_mm', [0, 0, 0])
    return frame[0], [a + b for a, b in zip(apply(frame[0], tool), frame[1])]


# ------------------------------------------------------------------ running dhcal




class Dhcal:
    def __init__(self, exe, scratch, wrapper=()):
        self.exe = exe
        self.scratch = scratch
        self.wrapper = list(wrapper)
        self.count = 0

    def path(self, name):
        return os.path.join(self.scratch, name)

    def run(self, *args):
        wrapper = self.wrapper if args[0] in ('import-urdf', 'export-urdf') else []
        return subprocess.run(wrapper + [self.exe] + list(args), capture_output=True, text=True,
                              timeout=300)

    def import_urdf(self, urdf, base, tip, out, tool=None):
        args = ['import-urdf', urdf, '--base', base, '--tip', tip, '--out', out]
        if tool is not None:
            args += ['--tool-mm', ','.join(repr(v) for v in tool)]
        return self.run(*args)

    def compare_max_mm(self, model_path, rows):
        """dhcal compare's largest tool-point error over rows [(q_deg, xyz_mm)]."""
        self.count += 1
        data = self.path(f'rows{self.count}.csv')
        n = len(rows[0][0])
        with open(data, 'w') as f:
            f.write(','.join([f'q{i + 1}' for i in range(n)] + ['x', 'y', 'z']) + '\n')
            for q, p in rows:
                f.write(','.join(repr(v) for v in list(q) + list(p)) + '\n')
        r = self.run('compare', '--model', model_path, '--data', data, '--json')
        if r.returncode != 0:
            raise RuntimeError(f'dhcal compare failed ({r.returncode}): {r.stderr}')
        return json.loads(r.stdout)['max_mm']


def reported_tip_rotation(stdout):
    """The tip rotation import-urdf reports (identity when it reports none)."""
    m = re.search(r'turned by rpy_deg \[([^,]+), ([^,]+), ([^\]]+)\]', stdout)
    if m is None:
        return IDENTITY[0]
    return rot_rpy(*(math.radians(float(v)) for v in m.groups()))


def random_q(rng, limits_rad):
    return [rng.uniform(lo, hi) for lo, hi in limits_rad]


def joint_limits(chain):
    out = []
    for j in chain:
        if j.get('type') == 'revolute':
            lim = j.find('limit')
            out.append((float(lim.get('lower')), float(lim.get('upper'))))
        elif j.get('type') == 'continuous':
            out.append((-2 * math.pi, 2 * math.pi))
    return out


def check_against_urdf(c, d, name, model_path, stdout, chain, qs, tool_mm=(0, 0, 0),
                       reference=None):
    """The imported model against the URDF's kinematics (or reference rows of (R, p)) at the
    joint angles qs (rad): tool points through dhcal compare and model_fk, frame N's
    orientation times the reported tip rotation against the tip's. Returns the numbers."""
    model = json.load(open(model_path))
    tip_in_n = reported_tip_rotation(stdout)
    rows, worst_p, worst_r = [], 0.0, 0.0
    for k, q in enumerate(qs):
        r_ref, p_ref = reference[k] if reference else urdf_fk(chain, q, tool_mm)
        r_n, p = model_fk(model, q)
        worst_p = max(worst_p, dist(p, p_ref))
        worst_r = max(worst_r, angle_between(matmul(r_n, tip_in_n), r_ref))
        rows.append(([math.degrees(v) for v in q], p_ref))
    via_dhcal = d.compare_max_mm(model_path, rows)
    c.check(f'{name}: tool point, dhcal compare', via_dhcal <= TOL_MM,
            f'max {via_dhcal:.3g} mm over {len(qs)} poses')
    c.check(f'{name}: tool point, model file formula', worst_p <= TOL_MM, f'max {worst_p:.3g} mm')
    c.check(f'{name}: tip orientation = frame N x reported rotation', worst_r <= TOL_RAD,
            f'max {worst_r:.3g} rad')
    return via_dhcal, worst_p, worst_r


def round_trip(c, d, name, model_path, n_joints, qs, reference, tip_in_n):
    """export-urdf, the exported URDF's own kinematics (urdf_fk) against the model's, then
    import-urdf world -> tool0 against the reference rows. tool0 is oriented as frame N: the
    reference tip orientations are turned back by tip_in_n, the rotation the first import
    reported."""
    exported = d.path(f'{name}-exported.urdf')
    r = d.run('export-urdf', model_path, '--out', exported)
    c.check(f'{name}: export-urdf exit 0', r.returncode == 0, r.stderr.strip())
    if r.returncode != 0:
        return
    model = json.load(open(model_path))
    chain = urdf_chain(exported, 'world', 'tool0')
    c.check(f'{name}: exported chain world -> tool0 has joint1..joint{n_joints}',
            [j.get('name') for j in chain if j.get('type') == 'revolute'] ==
            [f'joint{i + 1}' for i in range(n_joints)])
    worst_p = worst_r = 0.0
    for q in qs:
        r_u, p_u = urdf_fk(chain, q)
        r_m, p_m = model_fk(model, q)
        worst_p = max(worst_p, dist(p_u, p_m))
        worst_r = max(worst_r, angle_between(r_u, r_m))
    c.check(f'{name}: exported URDF kinematics = model (tool0 = tool point, frame N)',
            worst_p <= TOL_MM and worst_r <= TOL_RAD, f'max {worst_p:.3g} mm, {worst_r:.3g} rad')
    again = d.path(f'{name}-reimported.json')
    r = d.import_urdf(exported, 'world', 'tool0', again)
    c.check(f'{name}: re-import exit 0', r.returncode == 0, r.stderr.strip())
    if r.returncode == 0:
        frame_n = [(matmul(rot, transpose(tip_in_n)), p) for rot, p in reference]
        check_against_urdf(c, d, f'{name} round trip', again, r.stdout, None, qs,
                           reference=frame_n)


# ------------------------------------------------------------------ cases


def paper_arm(c, d, rng):
    chain = urdf_chain(PAPER_URDF, 'base_link', 'tool_flange')
    qs = [random_q(rng, joint_limits(chain)) for _ in range(200)]
    out = d.path('paper.json')
    r = d.import_urdf(PAPER_URDF, 'base_link', 'tool_flange', out)
    c.check('paper arm: import-urdf exit 0', r.returncode == 0, r.stderr.strip())
    if r.returncode != 0:
        return
    stdout = r.stdout
    check_against_urdf(c, d, 'paper arm', out, r.stdout, chain, qs)
    model = json.load(open(out))
    j = model['joints']
    c.check('paper arm: d1 433 mm, alpha1 90 deg, a2 400 mm, alpha2 0 (the paper)',
            abs(j[0]['d_mm'] - 433) < 1e-9 and abs(j[0]['alpha_deg'] - 90) < 1e-9 and
            abs(j[1]['a_mm'] - 400) < 1e-9 and abs(j[1]['alpha_deg']) < 1e-9,
            json.dumps(j[:2]))
    c.check('paper arm: joint 2 uses Hayati (beta_deg written), ranges +-170 deg',
            'beta_deg' in j[1] and all(abs(x['min_deg'] + 170) < 1e-9 and
                                       abs(x['max_deg'] - 170) < 1e-9 for x in j))
    c.check('paper arm: the flange rotation the model cannot carry is reported',
            angle_between(reported_tip_rotation(r.stdout), IDENTITY[0]) > 0.1, r.stdout)
    # the hand-written URDF is the paper's arm: its tool point against paper-3dof.json
    rows = [([math.degrees(v) for v in q], urdf_fk(chain, q)[1]) for q in qs]
    paper = d.compare_max_mm(PAPER_MODEL, rows)
    c.check('paper arm: the URDF is examples/models/paper-3dof.json (dhcal compare)',
            paper <= TOL_MM, f'max {paper:.3g} mm')
    # from the world link, through the 0.7 rad mount, with a tool point
    tool = (10.0, -20.0, 30.0)
    world_chain = urdf_chain(PAPER_URDF, 'world', 'tool_flange')
    out2 = d.path('paper-world.json')
    r = d.import_urdf(PAPER_URDF, 'world', 'tool_flange', out2, tool)
    c.check('paper arm from world, --tool-mm: exit 0', r.returncode == 0, r.stderr.strip())
    if r.returncode == 0:
        check_against_urdf(c, d, 'paper arm from world with tool', out2, r.stdout, world_chain,
                           qs, tool)
    reference = [urdf_fk(chain, q) for q in qs]
    round_trip(c, d, 'paper arm', out, 3, qs, reference, reported_tip_rotation(stdout))


def random_urdf(rng, index):
    """A random serial chain: 1..7 revolute or continuous joints with random origins and axes
    (some negative, some nearly parallel to the previous axis, tilted by less than 1e-3 rad),
    fixed joints between some of them."""
    n = rng.randint(1, 7)
    lines = [f'<robot name="random{index}">', '  <link name="l0"/>']
    link, k, previous_axis = 0, 0, None

    def joint(kind, axis=None, limit=None):
        nonlocal link
        xyz = ' '.join(repr(rng.uniform(-0.4, 0.4)) for _ in range(3))
        rpy = ' '.join(repr(rng.uniform(-math.pi, math.pi)) for _ in range(3))
        if axis is not None and previous_axis is not None and rng.random() < 0.3:
            rpy = '0 0 0'  # keeps the previous joint frame's directions: axes nearly parallel
        lines.append(f'  <link name="l{link + 1}"/>')
        lines.append(f'  <joint name="j{link + 1}" type="{kind}"><parent link="l{link}"/>'
                     f'<child link="l{link + 1}"/><origin xyz="{xyz}" rpy="{rpy}"/>')
        if axis is not None:
            lines.append(f'    <axis xyz="{" ".join(repr(v) for v in axis)}"/>')
        if limit is not None:
            lines.append(f'    <limit lower="{limit[0]!r}" upper="{limit[1]!r}" effort="1" '
                         f'velocity="1"/>')
        lines.append('  </joint>')
        link += 1

    while k < n:
        if rng.random() < 0.3:
            joint('fixed')
        if previous_axis is not None and rng.random() < 0.3:
            tilt = rng.uniform(-5e-4, 5e-4)  # |sin| < 1e-3: Hayati, with a real tilt
            axis = apply(rot_x(tilt), previous_axis)
        else:
            axis = [rng.choice([-1.0, 1.0]) * rng.uniform(0.05, 1.0) for _ in range(3)]
        kind = 'continuous' if rng.random() < 0.2 else 'revolute'
        lo = rng.uniform(-3.0, 0.0)
        joint(kind, axis, None if kind == 'continuous' else (lo, lo + rng.uniform(0.5, 3.0)))
        previous_axis, k = axis, k + 1
    if rng.random() < 0.5:
        joint('fixed')
    lines.append('</robot>')
    return '\n'.join(lines) + '\n', link


def random_chains(c, d, rng, count):
    worst = [0.0, 0.0, 0.0]
    continuous_ok = True
    for i in range(count):
        text, last = random_urdf(rng, i)
        path = d.path(f'random{i}.urdf')
        with open(path, 'w') as f:
            f.write(text)
        chain = urdf_chain(path, 'l0', f'l{last}')
        qs = [random_q(rng, joint_limits(chain)) for _ in range(40)]
        tool = tuple(rng.uniform(-100, 100) for _ in range(3))
        out = d.path(f'random{i}.json')
        r = d.import_urdf(path, 'l0', f'l{last}', out, tool)
        if r.returncode != 0:
            c.check(f'random chain {i}: import exit 0', False, r.stderr.strip())
            continue
        sub = Checks()
        numbers = check_against_urdf(sub, d, f'random chain {i}', out, r.stdout, chain, qs, tool)
        worst = [max(a, b) for a, b in zip(worst, numbers)]
        if sub.failed:
            c.check(f'random chain {i}', False, text)
        model = json.load(open(out))
        moving = [j for j in chain if j.get('type') != 'fixed']
        for j, mj in zip(moving, model['joints']):
            if j.get('type') == 'continuous':
                continuous_ok &= mj['min_deg'] == -720 and mj['max_deg'] == 720
            else:
                lim = j.find('limit')
                continuous_ok &= abs(math.radians(mj['min_deg']) - float(lim.get('lower'))) < 1e-15
    c.check(f'{count} random chains: tool point (dhcal compare), model formula, orientation',
            worst[0] <= TOL_MM and worst[1] <= TOL_MM and worst[2] <= TOL_RAD,
            f'max {worst[0]:.3g} mm, {worst[1]:.3g} mm, {worst[2]:.3g} rad')
    c.check('random chains: ranges kept, continuous joints +-720 deg', continuous_ok)


def chain_urdf(name, joints):
    """A URDF of links l0..lN from (type, xyz, rpy, axis) tuples (axis None for fixed)."""
    lines = [f'<robot name="{name}">', '  <link name="l0"/>']
    for k, (kind, xyz, rpy, axis) in enumerate(joints):
        lines.append(f'  <link name="l{k + 1}"/>')
        lines.append(f'  <joint name="j{k + 1}" type="{kind}"><parent link="l{k}"/>'
                     f'<child link="l{k + 1}"/><origin xyz="{xyz}" rpy="{rpy}"/>')
        if axis is not None:
            lines.append(f'    <axis xyz="{axis}"/>')
        if kind == 'revolute':
            lines.append('    <limit lower="-3" upper="3" effort="1" velocity="1"/>')
        lines.append('  </joint>')
    lines.append('</robot>')
    return '\n'.join(lines) + '\n', len(joints)


# Degenerate geometry a random chain hardly ever draws.
SPECIAL_CHAINS = {
    'coincident axes (a = 0, x kept)': [
        ('revolute', '0 0 0.1', '0 0 0', '0 0 1'), ('revolute', '0 0 0.2', '0 0 0.4', '0 0 1'),
        ('revolute', '0.3 0 0', '0 0 0', '0 1 0')],
    'antiparallel axes (Hayati, alpha 180)': [
        ('revolute', '0 0 0', '0 0 0', '0 1 0'), ('revolute', '0.4 0.1 0', '0 0 0', '0 -1 0'),
        ('revolute', '0.3 0 0.05', '0 0 0', '0 1 0')],
    'axis 1 along the base x (frame 0 x from y)': [
        ('revolute', '0.1 0.2 0.3', '0 0 0', '1 0 0'), ('revolute', '0.2 0 0', '0 0 0', '0 0 -1'),
        ('fixed', '0 0.1 0', '0.5 0.2 0.1', None)],
    'tip turned 90 deg about x, a continuous joint': [
        ('revolute', '0 0 0.2', '0 0 0', '0 0 1'), ('continuous', '0 0 0.3', '0 0 0', '0 1 0'),
        ('fixed', '0.2 0 0', '1.5707963267948966 0 0.3', None)],
    'tip y along the last axis (gimbal lock of the z-x-y angles)': [
        ('revolute', '0 0 0.2', '0 0 0', '0 0 1'), ('revolute', '0 0 0.3', '0 0 0', '0 1 0'),
        ('fixed', '0.2 0.01 0', '0 0.7 0', None)],
    'tip z against the last axis, -z axes': [
        ('revolute', '0 0 0.2', '0 0 0', '0 0 -1'), ('revolute', '0 0 0.3', '3.14159 0 0', '0 0 -1'),
        ('fixed', '0 0 0.1', '3.141592653589793 0 0', None)],
    'one joint, fixed joints around it': [
        ('fixed', '0.1 0 0', '0.1 0.2 0.3', None), ('revolute', '0 0.2 0', '0 0 0', '0 1 1'),
        ('fixed', '0 0 0.05', '0 0 0', None), ('fixed', '0.01 0.02 0.03', '0.3 0 0', None)],
}


def special_chains(c, d, rng):
    for name, joints in SPECIAL_CHAINS.items():
        text, last = chain_urdf('special', joints)
        path = d.path('special.urdf')
        with open(path, 'w') as f:
            f.write(text)
        chain = urdf_chain(path, 'l0', f'l{last}')
        qs = [random_q(rng, joint_limits(chain)) for _ in range(40)]
        out = d.path('special.json')
        r = d.import_urdf(path, 'l0', f'l{last}', out, (5.0, -7.0, 11.0))
        c.check(f'{name}: import exit 0', r.returncode == 0, r.stderr.strip())
        if r.returncode == 0:
            check_against_urdf(c, d, name, out, r.stdout, chain, qs, (5.0, -7.0, 11.0))


def export_comment(c, d):
    """Effects, measurer and gravity are listed in a comment; the file is XML that re-imports."""
    model = json.load(open(PAPER_MODEL))
    model['effects'] = {'joint_scale:1': [0.001], 'joint_compliance:2': [7.3e-05, 8.7e-05]}
    src = d.path('effects--model.json')  # '--' in the name: not allowed inside a comment
    with open(src, 'w') as f:
        json.dump(model, f)
    out = d.path('effects.urdf')
    r = d.run('export-urdf', src, '--out', out)
    c.check('export with effects: exit 0', r.returncode == 0, r.stderr.strip())
    if r.returncode != 0:
        return
    text = open(out).read()
    comments = ' '.join(re.findall(r'<!--(.*?)-->', text, re.S))
    c.check('export: effects, measurer and gravity listed in a comment',
            'joint_scale:1: 0.001' in comments and 'joint_compliance:2: 7.3e-05 8.7e-05' in comments
            and 'anchors_mm' in comments and 'gravity' in comments, comments)
    try:
        root = ET.parse(out).getroot()
        parsed = root.tag == 'robot'
    except ET.ParseError as e:
        parsed = False
        print(e)
    c.check('export: well-formed XML', parsed)
    names = [l.get('name') for l in root.findall('link')] if parsed else []
    c.check('export: links world, base_link, link1..3, flange, tool0',
            names == ['world', 'base_link', 'link1', 'link2', 'link3', 'flange', 'tool0'],
            str(names))
    # what the effects left out cost, against the same computed here: joint_scale:1 alone
    # (q1 -> (1 + s) q1), RMS over poses uniform in the joint ranges, Monte Carlo
    model['effects'] = {'joint_scale:1': [0.001]}
    src = d.path('scale-model.json')
    with open(src, 'w') as f:
        json.dump(model, f)
    r = d.run('export-urdf', src, '--out', d.path('scale.urdf'))
    said = re.search(r'move the model\'s tool point by ([0-9.e+-]+) mm RMS, ([0-9.e+-]+) mm at '
                     r'most', r.stdout)
    rng = random.Random(17)
    lims = [(math.radians(j.get('min_deg', -180.0)), math.radians(j.get('max_deg', 180.0)))
            for j in model['joints']]
    sq = []
    for _ in range(20000):
        q = [rng.uniform(lo, hi) for lo, hi in lims]
        moved = [q[0] * 1.001] + q[1:]
        sq.append(dist(model_fk(model, q)[1], model_fk(model, moved)[1]) ** 2)
    expect = math.sqrt(sum(sq) / len(sq))
    c.check('export: the effects left out, measured as here (RMS within 5 %)',
            said is not None and abs(float(said.group(1)) - expect) <= 0.05 * expect and
            float(said.group(2)) >= float(said.group(1)),
            f'{said.group(0) if said else r.stdout.strip()}; computed here {expect:.4g} mm RMS')


BAD_CASES = [
    # name, URDF text, base, tip, message pattern (after "file:")
    ('malformed XML', '<robot name="r">\n  <link name="a">\n  </joint>\n  <link name="b"/>\n'
     '</robot>\n', 'a', 'b', r':3: XML error: Opening and ending tag mismatch'),
    ('missing link (--tip)', None, 'base_link', 'no_such_link',
     r":\d+: the robot has no link 'no_such_link' \(--tip\)"),
    ('missing link (a joint\'s child)', 'child', 'base_link', 'tool_flange',
     r":39: joint 'elbow': child link 'forearm' is not a link of the robot"),
    ('prismatic joint in the chain', 'prismatic', 'base_link', 'tool_flange',
     r":32: joint 'shoulder' is prismatic"),
    ('NaN in an origin', 'nan', 'base_link', 'tool_flange',
     r':43: joint \'elbow\': <origin xyz="0 nan 0.4">: expected three finite numbers'),
    ('Inf in a limit', 'inf', 'base_link', 'tool_flange',
     r':37: joint \'shoulder\': <limit lower="-inf">: expected a finite number'),
    ('tip not below base', None, 'forearm', 'column', r":\d+: link 'column' \(--tip\) is not below"),
    ('no revolute joint between the links', None, 'forearm', 'tool_flange',
     r":16: no revolute or continuous joint between link 'forearm' and link 'tool_flange'"),
    ('nearly parallel axes (a DH length beyond 1e5 mm)', 'skew', 'base_link', 'tool_flange',
     r":32: joint 'shoulder': its DH lengths \(a [-0-9.e+]+ mm, d [-0-9.e+]+ mm\) exceed"),
    ('a link with two parents', 'two-parents', 'base_link', 'tool_flange',
     r":48: link 'forearm' is the child of joint 'elbow' \(line 40\) and of joint 'flange': "
     r"not a tree"),
]


def bad_input(c, d):
    paper = open(PAPER_URDF).read()
    variants = {
        'child': paper.replace('<link name="forearm"/>\n', ''),
        # elbow's axis 0.0015 rad off the shoulder's: |sin| above the Hayati threshold, the
        # common normal 0.4 m / 0.0015 = 270 m away
        'skew': paper.replace('<origin xyz="0 0.05 0.4" rpy="0 0 0"/>',
                              '<origin xyz="0 0.05 0.4" rpy="0.0015 0 0"/>'),
        'two-parents': paper.replace('<child link="tool_flange"/>', '<child link="forearm"/>'),
        'prismatic': paper.replace('name="shoulder" type="revolute"', 'name="shoulder" type="prismatic"'),
        'nan': paper.replace('xyz="0 0.05 0.4"', 'xyz="0 nan 0.4"'),
        'inf': paper.replace('<limit lower="-2.9670597283903604" upper="2.9670597283903604" '
                             'effort="100" velocity="1"/>\n  </joint>\n\n  <joint name="elbow"',
                             '<limit lower="-inf" upper="2.9670597283903604" effort="100" '
                             'velocity="1"/>\n  </joint>\n\n  <joint name="elbow"', 1),
    }
    existing = d.path('existing.json')
    original = b'{"keep": "me"}\n'
    for name, text, base, tip, pattern in BAD_CASES:
        path = d.path('bad.urdf')
        with open(path, 'w') as f:
            f.write(variants.get(text, text) if text is not None else paper)
        with open(existing, 'wb') as f:
            f.write(original)
        r = d.import_urdf(path, base, tip, existing)
        ok = r.returncode == 2 and re.search(re.escape(path) + pattern, r.stderr) is not None
        kept = open(existing, 'rb').read() == original
        leftovers = [f for f in os.listdir(d.scratch) if f.startswith('existing.json.tmp')]
        c.check(f'bad input, {name}: exit 2, file:line named, --out untouched',
                ok and kept and not leftovers, f'exit {r.returncode}: {r.stderr.strip()}')
    with open(existing, 'wb') as f:
        f.write(original)
    r = d.run('export-urdf', PAPER_URDF, '--out', existing)  # a URDF is not a model file
    c.check('export-urdf of a file that is no model: exit 2, --out untouched',
            r.returncode == 2 and open(existing, 'rb').read() == original, r.stderr.strip())
    r = d.run('import-urdf', PAPER_URDF, '--base', 'base_link', '--out', existing)
    c.check('import-urdf without --tip: usage error, exit 2', r.returncode == 2, r.stderr.strip())
    r = d.run('import-urdf', PAPER_URDF, '--base', 'base_link', '--tip', 'tool_flange',
              '--tool-mm', '1,nan,3', '--out', existing)
    c.check('import-urdf --tool-mm with NaN: exit 2', r.returncode == 2, r.stderr.strip())


# ------------------------------------------------------------------ real robots


ROBOTS = [('ur5', 'base_link', 'tool0'), ('ur10', 'base_link', 'tool0'),
          ('panda', 'panda_link0', 'panda_link8'), ('iiwa14', 'iiwa_link_0', 'iiwa_link_ee_kuka')]


def read_fk_table(path):
    """Rows (q_rad, R, p_mm) of a <robot>.fk.csv."""
    lines = [l for l in open(path).read().splitlines() if l and not l.startswith('#')]
    header = lines[0].split(',')
    n = sum(1 for h in header if re.fullmatch(r'q\d+', h))
    rows = []
    for l in lines[1:]:
        v = [float(x) for x in l.split(',')]
        q = [math.radians(x) for x in v[:n]]
        p = v[n:n + 3]
        rows.append((q, rot_quat(*v[n + 3:n + 7]), p))
    return rows


def real_robots(c, d, realdata):
    urdf_dir = os.path.join(realdata, 'urdf')
    for robot, base, tip in ROBOTS:
        urdf = os.path.join(urdf_dir, f'{robot}.urdf')
        rows = read_fk_table(os.path.join(urdf_dir, f'{robot}.fk.csv'))
        qs = [q for q, _, _ in rows]
        reference = [(r, p) for _, r, p in rows]
        out = d.path(f'{robot}.json')
        r = d.import_urdf(urdf, base, tip, out)
        c.check(f'{robot}: import-urdf {base} -> {tip} exit 0', r.returncode == 0,
                r.stderr.strip())
        if r.returncode != 0:
            continue
        check_against_urdf(c, d, f'{robot} vs {robot}.fk.csv', out, r.stdout, None, qs,
                           reference=reference)
        round_trip(c, d, robot, out, len(qs[0]), qs, reference, reported_tip_rotation(r.stdout))
    ur5_against_jacobi(c, d, realdata)


def ur5_against_jacobi(c, d, realdata):
    """The imported UR5 against the UR5 model file of ur5-jacobi (the Robotics Toolbox's DH):
    T_DH = Rz(180 deg) T_urdf (urdf/README.md), tool0 = DH frame 6, so the jacobi model's tool
    point is --tool-mm in tool0."""
    jacobi_path = os.path.join(realdata, 'ur5-jacobi', 'model.json')
    jacobi = json.load(open(jacobi_path))
    out = d.path('ur5-jacobi-tool.json')
    r = d.import_urdf(os.path.join(realdata, 'urdf', 'ur5.urdf'), 'base_link', 'tool0', out,
                      jacobi['tool_mm'])
    c.check('ur5 with the jacobi tool: import exit 0', r.returncode == 0, r.stderr.strip())
    if r.returncode != 0:
        return
    imported = json.load(open(out))
    tip_in_n = reported_tip_rotation(r.stdout)
    rng = random.Random(16)
    turn = rot_z(math.pi)
    rows, worst_p, worst_r = [], 0.0, 0.0
    for _ in range(200):
        q = [rng.uniform(-2 * math.pi, 2 * math.pi) for _ in range(6)]
        r_imp, p_imp = model_fk(imported, q)
        r_dh, p_dh = model_fk(jacobi, q)
        p_turned = apply(turn, p_imp)
        worst_p = max(worst_p, dist(p_turned, p_dh))
        worst_r = max(worst_r, angle_between(matmul(turn, matmul(r_imp, tip_in_n)), r_dh))
        rows.append(([math.degrees(v) for v in q], p_turned))
    via_dhcal = d.compare_max_mm(jacobi_path, rows)
    c.check('ur5: imported model = ur5-jacobi model (Rz(180 deg) base), tool point',
            worst_p <= TOL_MM and via_dhcal <= TOL_MM,
            f'max {worst_p:.3g} mm (formula), {via_dhcal:.3g} mm (dhcal compare on the jacobi '
            f'model)')
    c.check('ur5: frame 6 orientation = jacobi frame 6', worst_r <= TOL_RAD, f'max {worst_r:.3g} rad')


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--dhcal', required=True)
    ap.add_argument('--scratch', required=True)
    ap.add_argument('--realdata')
    ap.add_argument('--wrapper', default='')
    args = ap.parse_args()
    os.makedirs(args.scratch, exist_ok=True)
    d = Dhcal(args.dhcal, args.scratch, shlex.split(args.wrapper))
    c = Checks()
    if args.realdata is not None:
        needed = [os.path.join(args.realdata, 'urdf', f'{r}.fk.csv') for r, _, _ in ROBOTS]
        needed.append(os.path.join(args.realdata, 'ur5-jacobi', 'model.json'))
        missing = [p for p in needed if not os.path.isfile(p)]
        if missing:
            print(f'SKIP: the real robots are not here ({missing[0]} missing); '
                  'set DHCAL_REALDATA_DIR to the folder of ../shared/realdata')
            return SKIP
        real_robots(c, d, args.realdata)
    else:
        rng = random.Random(1616)
        paper_arm(c, d, rng)
        random_chains(c, d, rng, 40)
        special_chains(c, d, rng)
        export_comment(c, d)
        bad_input(c, d)
    print(f'{c.passed} passed, {c.failed} failed')
    return 1 if c.failed or c.passed == 0 else 0


if __name__ == '__main__':
    sys.exit(main())
