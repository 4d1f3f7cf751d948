#!/usr/bin/env python3
"""Writes the seed corpora of tests/fuzz/corpus/ (checked in; rerun after changing a
target's input layout). Text targets (csv, model, scenario) get the example files plus small
hand-made files for each accepted feature and a few rejected ones; binary targets (trilat,
lsq, predict) get inputs encoded the way their fz_reader decodes them (fuzz_common.h):
plausible geometry, the edge cases their headers name, and non-finite values.

Usage: tests/fuzz/make_seeds.py   (from anywhere; writes next to itself)
"""
import math
import os
import shutil
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
CORPUS = os.path.join(HERE, 'corpus')
DEG = math.pi / 180.0


def put(target, name, data):
    d = os.path.join(CORPUS, target)
    os.makedirs(d, exist_ok=True)
    mode = 'wb' if isinstance(data, bytes) else 'w'
    with open(os.path.join(d, name), mode) as f:
        f.write(data)


# ---------------------------------------------------------------- fz_reader encoding
def u8(v):
    return bytes([v & 0xFF])


def dbl(v):
    """fz_double, tag 0: the raw IEEE bits, big-endian as fz_u64 reads them."""
    return b'\x00' + struct.pack('>d', v)


SPECIAL = {'nan': 6, 'inf': 4, '-inf': 5, 'max': 7, 'zero': 0}


def special(name):
    """fz_double, tag 3: an entry of the special-value table."""
    return u8(3 | (SPECIAL[name] << 2))


# ---------------------------------------------------------------- trilat
def paper_measurer_point(q):
    a, b, c = 1200.0, 600.0, 300.0
    anchors = [(0, 0, a), (0, b, c), (0, -b, c)]
    return [math.dist(q, p) for p in anchors]


def trilat(a, b, c, sign_tag, frame, lengths, tol):
    out = dbl(a) + dbl(b) + dbl(c) + u8(sign_tag)
    if frame is None:  # xyz + rpy
        out += u8(0) + b''.join(dbl(v) for v in (1300.0, 0.0, 0.0, 0.0, 0.0, math.pi))
    else:  # twelve raw doubles: row by row, rotation then position
        out += u8(1) + b''.join(dbl(v) for v in frame)
    return out + b''.join(x if isinstance(x, bytes) else dbl(x) for x in lengths) + dbl(tol)


def trilat_seeds():
    inside = paper_measurer_point((400.0, 120.0, 700.0))
    put('trilat', 'paper-point', trilat(1200, 600, 300, 1, None, inside, 1e-6))
    put('trilat', 'negative-side', trilat(1200, 600, 300, 2, None,
                                          paper_measurer_point((-250.0, -80.0, 900.0)), 0.0))
    put('trilat', 'on-anchor-plane', trilat(1200, 600, 300, 1, None,
                                            paper_measurer_point((0.0, 50.0, 800.0)), 1e-9))
    put('trilat', 'inconsistent', trilat(1200, 600, 300, 1, None, [100.0, 2000.0, 100.0], 1e-6))
    put('trilat', 'nan-length', trilat(1200, 600, 300, 1, None,
                                       [inside[0], special('nan'), inside[2]], 1e-6))
    put('trilat', 'huge-lengths', trilat(1200, 600, 300, 1, None, [1e200, 1e200, 1e200], 1.0))
    put('trilat', 'collinear-anchors', trilat(300, 600, 300, 1, None, inside, 1e-6))
    put('trilat', 'raw-frame', trilat(1200, 600, 300, 1,
                                      [1, 0, 0, 10, 0, 1, 0, 20, 0, 0, 1, 30], inside, 1e-6))
    put('trilat', 'far-origin', trilat(1e6 + 1200, 600, 1e6 + 300, 1, None,
                                       [math.dist((60.0, 10.0, 1e6 + 500.0), p) for p in
                                        [(0, 0, 1e6 + 1200), (0, 600, 1e6 + 300),
                                         (0, -600, 1e6 + 300)]], 1e-6))


# ---------------------------------------------------------------- lsq
def lsq(n, blocks, opts=0, rel_tol=None, lam=None, sigma2=None):
    """blocks: list of (rows, residuals, weights or None); rows are k lists of n values,
    or a column spec per column: ('same', src) / ('scale', src, f) / ('zero',)."""
    out = u8(n - 1) + u8(len(blocks))
    for cols, res, w in blocks:
        k = len(res)
        out += u8(k - 1)
        for spec in cols:
            if spec[0] == 'draw':
                out += u8(0) + b''.join(v if isinstance(v, bytes) else dbl(v) for v in spec[1])
            elif spec[0] == 'zero':
                out += u8(1)
            elif spec[0] == 'scale':
                out += u8(2 | (spec[1] << 2)) + dbl(spec[2])
            else:
                out += u8(3 | (spec[1] << 2))
        out += b''.join(dbl(v) if not isinstance(v, bytes) else v for v in res)
        out += u8(1 if w is not None else 0)
        if w is not None:
            out += b''.join(dbl(v) for v in w)
    out += u8(opts)
    if opts & 1:
        out += dbl(rel_tol)
    if opts & 2:
        out += dbl(lam)
    if opts & 4:
        out += dbl(sigma2)
    return out


def lsq_seeds():
    draw = lambda *v: ('draw', list(v))  # noqa: E731
    well = [([draw(1, 0, 2), draw(0, 1, 1), draw(3, 1, 0)], [0.5, -1, 2], None),
            ([draw(2, 1, 0), draw(1, 1, 1), draw(0, 2, 5)], [1, 1, -3], [1, 2, 0.5])]
    put('lsq', 'well-posed', lsq(3, well))
    put('lsq', 'rank-deficient', lsq(3, [([draw(1, 2, 3, 4), draw(0, 1, 0, 1), ('scale', 0, 2.0)],
                                          [1, 2, 3, 4], None)]))
    put('lsq', 'zero-column', lsq(3, [([draw(1, 2, 3), ('zero',), draw(5, 0, 1)], [1, 0, 2], None)]))
    put('lsq', 'nan-residual', lsq(2, [([draw(1, 2), draw(0, 1)], [1, special('nan')], None)]))
    put('lsq', 'inf-entry', lsq(2, [([draw(1, special('inf')), draw(0, 1)], [1, 1], None)]))
    put('lsq', 'bad-weight', lsq(2, [([draw(1, 2), draw(3, 4)], [1, 1], [1.0, -1.0])]))
    put('lsq', 'huge-scale', lsq(2, [([draw(1e150, 2e150), draw(1e-150, 3e-150)], [1e150, 1],
                                       None)]))
    put('lsq', 'options', lsq(3, well, 7, 1e-6, 10.0, 0.25))
    put('lsq', 'no-rows', lsq(4, []))


# ---------------------------------------------------------------- predict
class PredictWriter:
    """Mirrors read_model / read_sample / read_params of fuzz_predict.c. maybe() fields are
    collected first (their mask bytes precede them), then emitted."""

    def __init__(self):
        self.maybes = []

    def encode(self, build):
        self.maybes = []
        build(self, collect=True)
        self.queue = list(self.maybes)
        self.bit = 8
        self.out = b''
        build(self, collect=False)
        return self.out

    def raw(self, b, collect):
        if not collect:
            self.out += b

    def maybe(self, v, collect):
        if collect:
            self.maybes.append(v)
            return
        if self.bit == 8:
            nxt = self.queue[:8]
            mask = sum(1 << i for i, x in enumerate(nxt) if x is not None)
            self.out += u8(mask)
            self.bit = 0
        v = self.queue.pop(0)
        self.bit += 1
        if v is not None:
            self.out += v if isinstance(v, bytes) else dbl(v)


def frame_xyz_rpy(xyz, rpy):
    return u8(0) + b''.join(dbl(v) for v in list(xyz) + list(rpy))


def predict(joints, q, kind=0, dirs=None, measurer=None, effects=(), extra=(), temp=None,
            p=(0, 0, 0), wires=(1, 1, 1), weight=None, thermal=(None, None), tool=(None,) * 3):
    """joints: list of dicts (theta, d, a, alpha, beta, scale, hs, hc, backlash, c: list)."""
    n = len(joints)

    def build(w, collect):
        w.raw(u8(n - 1), collect)
        for i, j in enumerate(joints):
            for key in ('theta', 'd', 'a', 'alpha', 'beta', 'scale', 'hs', 'hc', 'backlash'):
                w.maybe(j.get(key), collect)
            c = j.get('c', [None] * (n - i))
            for k in range(n - i):
                w.maybe(c[k], collect)
        w.raw(u8(0), collect)  # base: identity
        for k in range(3):
            w.maybe(tool[k], collect)
            w.maybe(None, collect)  # gravity as initialised
        w.raw(u8(1 if measurer else 0), collect)
        if measurer:
            for k in range(3):
                w.raw(b''.join(dbl(v) for v in measurer['anchors'][k]), collect)
                w.maybe(measurer.get('offset', [None] * 3)[k], collect)
            w.raw(frame_xyz_rpy(measurer['xyz'], measurer['rpy']), collect)
            w.maybe(measurer.get('scale'), collect)
        w.maybe(thermal[0], collect)
        w.maybe(thermal[1], collect)
        # sample
        w.raw(u8(kind), collect)
        for i in range(n):
            w.raw(dbl(q[i]) if not isinstance(q[i], bytes) else q[i], collect)
            d = 0 if dirs is None else dirs[i]
            w.raw(u8(d + 1 if d in (-1, 0, 1) else 0x80 | (d + 64)), collect)
        w.raw(u8(0) if temp is None else u8(1) + dbl(temp), collect)
        for k in range(3):
            w.raw(dbl(p[k]) + dbl(wires[k]), collect)
        w.raw(frame_xyz_rpy((0, 0, 0), (0.1, 0.2, 0.3)), collect)
        w.raw(u8(len(extra)) + b''.join(u8(e % 10 | (jj << 4)) for e, jj in extra), collect)
        w.raw(u8(0) if weight is None else u8(1) + dbl(weight), collect)

    return PredictWriter().encode(build)


def predict_seeds():
    paper3 = [dict(d=433.0, alpha=90 * DEG), dict(a=400.0), dict(a=345.0)]
    meas = dict(anchors=[(0, 0, 1200), (0, 600, 300), (0, -600, 300)], xyz=(1300, 0, 0),
                rpy=(0, 0, math.pi))
    q = [0.3, 1.1, -0.7]
    put('predict', 'paper3-position', predict(paper3, q, 0, p=(400, 100, 900)))
    put('predict', 'paper3-pose', predict(paper3, q, 1, extra=[(0, 0), (1, 0)]))
    put('predict', 'paper3-wires', predict(paper3, q, 2, measurer=dict(meas, scale=1e-3,
                                                                       offset=[0.5, -0.2, 0.1]),
                                           wires=(900, 1000, 1100), extra=[(6, 0), (7, 0), (8, 0)]))
    fx = [dict(j) for j in paper3]
    fx[1].update(scale=1e-3, hs=1e-4, hc=-2e-4, backlash=5e-4, c=[1e-6, 2e-6])
    put('predict', 'paper3-effects', predict(fx, q, 0, dirs=[1, -1, 1], temp=35.0,
                                             thermal=(1.2e-5, 20.0),
                                             extra=[(2, 1), (3, 1), (4, 1), (5, 1), (9, 0)]))
    put('predict', 'nan-angle', predict(paper3, [0.3, dbl(math.nan), 0.1], 0))
    put('predict', 'bad-direction', predict(paper3, q, 0, dirs=[1, 5, -1]))
    put('predict', 'thermal-zero-scale', predict(paper3, q, 0, temp=120.0, thermal=(-0.01, 20.0),
                                                 extra=[(9, 0)]))
    put('predict', 'huge-link', predict([dict(a=1e300), dict(a=1e300)], [0.0, 0.0], 0))
    six = [dict(alpha=-90 * DEG, d=400), dict(a=560), dict(a=35, alpha=-90 * DEG),
           dict(d=515, alpha=90 * DEG), dict(alpha=-90 * DEG), dict(d=80)]
    put('predict', 'six-joints-pose', predict(six, [0.1, -0.4, 0.2, 0.3, -0.2, 0.5], 1,
                                              tool=(0, 0, 100), weight=500.0))


# ---------------------------------------------------------------- csv
def csv_seeds():
    for f in ('train.csv', 'heldout.csv'):
        shutil.copy(os.path.join(ROOT, 'examples', 'data', 'compliance', f),
                    os.path.join(CORPUS, 'csv', 'example-' + f))
    put('csv', 'xyz', 'q1,q2,q3,x,y,z\n10,20,30,400,100,900\n-5,45,-60,300,-50,700\n')
    put('csv', 'wires', '# raw wire lengths\nq1,q2,q3,L1,L2,L3\n10,20,30,900,1000,1100\n')
    put('csv', 'pose-dir-temp',
        'x, y, z, q3, q2, q1, qw, qx, qy, qz, dir1, dir2, dir3, temp_c\n'
        '400, 100, 900, 30, 20, 10, 1, 0, 0, 0, 1, -1, 1, 21.5\n'
        '410, 90, 880, 31, 19, 11, 0.7071068, 0.7071068, 0, 0, -1, -1, 1, 22\n')
    put('csv', 'crlf-bom-comments',
        b'\xef\xbb\xbf# BOM, CRLF\r\nq1,q2,q3,x,y,z,L1,L2,L3\r\n\r\n  # inside\r\n'
        b'1.5e1,+2,-3.25,4,5,6,7,8,9\r\n')
    put('csv', 'six-joints', 'q1,q2,q3,q4,q5,q6,x,y,z\n1,2,3,4,5,6,100,200,300\n')
    put('csv', 'one-joint', 'q1,x,y,z\n90,1,2,3\n')
    put('csv', 'short-row', 'q1,q2,q3,x,y,z\n1,2,3,4,5\n')
    put('csv', 'nan', 'q1,q2,q3,x,y,z\n1,2,3,nan,5,6\n')
    put('csv', 'range', 'q1,q2,q3,x,y,z,temp_c\n721,2,3,4,5,6e5,200\n')


# ---------------------------------------------------------------- model
def model_seeds():
    for f in ('paper-3dof.json', 'paper-6dof-nominal.json'):
        shutil.copy(os.path.join(ROOT, 'examples', 'models', f),
                    os.path.join(CORPUS, 'model', f))
    shutil.copy(os.path.join(ROOT, 'examples', 'data', 'compliance', 'model.json'),
                os.path.join(CORPUS, 'model', 'example-compliance-model.json'))
    put('model', 'minimal.json', '{"joints": [{"alpha_deg": 0, "a_mm": 100, "d_mm": 0}]}\n')
    put('model', 'every-effect.json', '''{"name": "all \\"effects\\"",
 "joints": [{"alpha_deg": 90, "a_mm": 0, "d_mm": 433, "min_deg": -170, "max_deg": 170},
            {"alpha_deg": 0, "a_mm": 400, "d_mm": 0, "beta_deg": 0.01},
            {"alpha_deg": 0, "a_mm": 345, "d_mm": 0, "theta_offset_deg": -1.5}],
 "tool_mm": [10, 0, 5],
 "base": {"xyz_mm": [1, 2, 3], "rpy_deg": [0.5, -90, 30]},
 "gravity": [0, 0.6, -0.8],
 "measurer": {"anchors_mm": [[0, 0, 1200], [0, 600, 300], [0, -600, 300]]},
 "effects": {"joint_scale:1": [1e-3], "joint_harmonic:2": [0.01, -0.02],
             "joint_backlash:3": [0.05], "joint_compliance:2": [1e-4, 2e-4],
             "measurer_scale": [1e-4], "measurer_offset": [0.1, 0.2, 0.3],
             "thermal_scale": [1.2e-5, 21]}}
''')
    put('model', 'misplaced-effect.json',
        '{"joints": [{"alpha_deg": 0, "a_mm": 1, "d_mm": 0}], "effects": {"tool_offset": [1]}}')
    put('model', 'syntax-error.json', '{"joints": [ {"alpha_deg": 90, ')
    put('model', 'wrong-type.json', '{"joints": [{"alpha_deg": "90", "a_mm": 0, "d_mm": 0}]}')


# ---------------------------------------------------------------- scenario
# fuzz_scenario.c puts paper-3dof-model.json (host_sim/scenarios) and
# paper-6dof-nominal.json (examples/models) next to the input: seeds name them.
def scenario_seeds():
    src = os.path.join(ROOT, 'host_sim', 'scenarios')
    for f in sorted(os.listdir(src)):
        if f.endswith('.json') and 'model' not in f:
            shutil.copy(os.path.join(src, f), os.path.join(CORPUS, 'scenario', f))
    link3 = ('[{"link": {"mass_kg": 5, "com_mm": [0, -216, 0]}}, '
             '{"link": {"mass_kg": 4, "com_mm": [-200, 0, 0]}}, '
             '{"link": {"mass_kg": 2, "com_mm": [-170, 0, 0]}}]')
    put('scenario', 'minimal.json',
        '{"seed": 3, "model": "paper-3dof-model.json", "joints": %s}\n' % link3)
    put('scenario', 'compliant-everything.json', '''{"seed": 9007199254740992,
 "model": "paper-3dof-model.json",
 "truth": {"joints": [{"theta_offset_deg": 1, "d_mm": 2, "a_mm": -3, "alpha_deg": 0.5},
                      {"beta_deg": 0.2}, {"a_mm": 1}],
           "base": {"xyz_mm": [1, 2, 3], "rpy_deg": [0.1, 0.2, 0.3]}, "tool_mm": [1, 0, 0],
           "random_sd": {"theta_offset_deg": 0.1, "d_mm": 0.1, "a_mm": 0.1,
                         "alpha_deg": 0.1, "beta_deg": 0.1}},
 "physics": {"step_us": 50, "gravity_mps2": 9.81},
 "joint_defaults": {"gear": {"ratio": 50, "backlash_deg": 0.1, "stiffness_nm_per_rad": 20000,
                             "transmission_error": [{"order": 2, "sin_mrad": 0.3}]},
                    "tacho": {"ripple": 0.1, "noise_v": 0.01},
                    "controller": {"gear_ratio": 50.5, "encoder_lines": 512}},
 "joints": %s,
 "payload": {"mass_kg": 1, "com_mm": [10, 0, 0], "inertia_kgm2": [0.01, 0.01, 0.01]},
 "drive": {"dac_range_v": 5, "adc_range_v": 5},
 "measurer": {"anchor_errors_mm": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
              "frame_error": {"xyz_mm": [1, 1, 1], "rpy_deg": [0.1, 0, 0]},
              "wheel_radius_mm": 10, "wheel_radius_error": 0.001, "lines": 1000,
              "counter_bits": 8, "zero_length_mm": [100, 100, 100],
              "zero_length_error_mm": [0.1, 0, 0], "slip_sd_mm_per_sqrt_mm": 0.01,
              "noise_mm": 0.01},
 "noise": {"xyz_mm": 0.05},
 "poses": {"min_axis_distance_mm": 100, "min_anchor_plane_mm": 100}}
''' % link3)
    put('scenario', 'model-6dof-wrong-joint-count.json',
        '{"seed": 1, "model": "paper-6dof-nominal.json", "joints": %s}\n' % link3)
    put('scenario', 'no-model-file.json',
        '{"seed": 1, "model": "missing.json", "joints": %s}\n' % link3)
    put('scenario', 'missing-seed.json',
        '{"model": "paper-3dof-model.json", "joints": %s}\n' % link3)
    put('scenario', 'nan.json',
        '{"seed": 1, "model": "paper-3dof-model.json", "joints": %s,'
        ' "noise": {"xyz_mm": NaN}}\n' % link3)
    put('scenario', 'negative-stiffness.json',
        '{"seed": 1, "model": "paper-3dof-model.json", "joints": %s,'
        ' "joint_defaults": {"gear": {"stiffness_nm_per_rad": -5}}}\n' % link3)
    put('scenario', 'unknown-key.json',
        '{"seed": 1, "model": "paper-3dof-model.json", "joints": %s, "bogus": 1}\n' % link3)
    put('scenario', 'repeated-key.json',
        '{"seed": 1, "seed": 2, "model": "paper-3dof-model.json", "joints": %s}\n' % link3)
    put('scenario', 'syntax-error.json', '{"seed": 1, "model": "paper-3dof-model.json", "jo')
    put('scenario', 'fractional-seed.json',
        '{"seed": 1.5, "model": "paper-3dof-model.json", "joints": %s}\n' % link3)


if __name__ == '__main__':
    if os.path.isdir(CORPUS):
        shutil.rmtree(CORPUS)
    for t in ('csv', 'model', 'trilat', 'lsq', 'predict', 'scenario'):
        os.makedirs(os.path.join(CORPUS, t))
    trilat_seeds()
    lsq_seeds()
    predict_seeds()
    csv_seeds()
    model_seeds()
    scenario_seeds()
    for t in sorted(os.listdir(CORPUS)):
        print('%-8s %d seeds' % (t, len(os.listdir(os.path.join(CORPUS, t)))))
