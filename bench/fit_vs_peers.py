#!/usr/bin/env python3
"""dhcal fit vs scipy.optimize.least_squares on the same problem, timed in one run.

Problem: the paper's 6-DOF arm (nominal Table 2, actual Table 1 with every joint offset
2 deg), N tool positions with Gaussian noise. dhcal runs as a whole process (start-up,
parsing the files, fitting, printing JSON). scipy gets only its solver call timed, on
vectorised numpy forward kinematics with the same parameters (Hayati beta in place of d
where Table 2 has alpha = 0), so the comparison favours scipy.

Usage: fit_vs_scipy.py --dhcal build/host/tools/dhcal [--poses 2000] [--repeat 3]
Prints the times and the ratio; exits 1 if the two RMS values disagree.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.optimize import least_squares

TABLE1 = [(91.2, 101.0, 201.0), (1.0, 104.0, 2.0), (1.8, 102.0, 100.1),
          (-92.1, -1.0, 12.0), (-0.8, 14.0, 110.0), (91.1, 3.0, 2.1)]
TABLE2 = [(90.0, 100.0, 200.0), (0.0, 100.0, 0.0), (0.0, 100.0, 100.0),
          (-90.0, 0.0, 10.0), (0.0, 10.0, 100.0), (90.0, 0.0, 0.0)]
# alpha = 0 in Table 2 and not the last joint: beta replaces d there.
HAYATI = [False, True, True, False, True, False]


def fk_points(q, theta, d, a, alpha, beta):
    """Tool points (origin of frame 6) for joint angles q (m x 6), vectorised over poses."""
    m = q.shape[0]
    rot = np.broadcast_to(np.eye(3), (m, 3, 3)).copy()
    pos = np.zeros((m, 3))
    for i in range(6):
        phi = q[:, i] + theta[i]
        c, s = np.cos(phi), np.sin(phi)
        ca, sa = np.cos(alpha[i]), np.sin(alpha[i])
        cb, sb = np.cos(beta[i]), np.sin(beta[i])
        # Rz(phi) Rx(alpha) Ry(beta), written out
        rzx = np.zeros((m, 3, 3))
        rzx[:, 0, 0], rzx[:, 0, 1], rzx[:, 0, 2] = c, -s * ca, s * sa
        rzx[:, 1, 0], rzx[:, 1, 1], rzx[:, 1, 2] = s, c * ca, -c * sa
        rzx[:, 2, 1], rzx[:, 2, 2] = sa, ca
        ry = np.array([[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]])
        local = np.stack([a[i] * c, a[i] * s, np.full(m, d[i])], axis=1)
        pos = pos + np.einsum('mij,mj->mi', rot, local)
        rot = np.einsum('mij,mjk->mik', rot, rzx @ ry)
    return pos


def unpack(p, nominal):
    theta, d, a, alpha, beta = (np.array(v, dtype=float) for v in nominal)
    for i in range(6):
        k = 4 * i
        theta[i] += p[k]
        if HAYATI[i]:
            beta[i] += p[k + 1]
        else:
            d[i] += p[k + 1]
        a[i] += p[k + 2]
        alpha[i] += p[k + 3]
    return theta, d, a, alpha, beta


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--dhcal', required=True)
    ap.add_argument('--poses', type=int, default=2000)
    ap.add_argument('--noise-mm', type=float, default=0.01)
    ap.add_argument('--repeat', type=int, default=3)
    args = ap.parse_args()

    rng = np.random.default_rng(20261121)
    deg = np.pi / 180.0
    truth = ([2.0 * deg] * 6, [r[2] for r in TABLE1], [r[1] for r in TABLE1],
             [r[0] * deg for r in TABLE1], [0.0] * 6)
    nominal = ([0.0] * 6, [r[2] for r in TABLE2], [r[1] for r in TABLE2],
               [r[0] * deg for r in TABLE2], [0.0] * 6)
    q = rng.uniform(-np.pi, np.pi, size=(args.poses, 6))
    meas = fk_points(q, *truth) + rng.normal(0.0, args.noise_mm, size=(args.poses, 3))

    with tempfile.TemporaryDirectory() as tmp:
        model = {"name": "paper-6dof", "joints": [
            {"alpha_deg": r[0], "a_mm": r[1], "d_mm": r[2], "theta_offset_deg": 0,
             "min_deg": -180, "max_deg": 180} for r in TABLE2]}
        model_path = os.path.join(tmp, 'model.json')
        data_path = os.path.join(tmp, 'data.csv')
        with open(model_path, 'w') as f:
            json.dump(model, f)
        with open(data_path, 'w') as f:
            f.write('q1,q2,q3,q4,q5,q6,x,y,z\n')
            for qi, pi in zip(q / deg, meas):
                f.write(','.join('%.12f' % v for v in qi) + ',' +
                        ','.join('%.9f' % v for v in pi) + '\n')

        dhcal_times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            out = subprocess.run([args.dhcal, 'fit', '--model', model_path, '--data', data_path,
                                  '--json'], check=True, capture_output=True, text=True)
            dhcal_times.append(time.perf_counter() - t0)
        dhcal_rms = json.loads(out.stdout)['rms_mm']

    def residuals(p):
        return (fk_points(q, *unpack(p, nominal)) - meas).ravel()

    scipy_times = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        sol = least_squares(residuals, np.zeros(24), x_scale='jac')
        scipy_times.append(time.perf_counter() - t0)
    r = sol.fun.reshape(-1, 3)
    scipy_rms = float(np.sqrt(np.mean(np.sum(r * r, axis=1))))

    td, ts = min(dhcal_times), min(scipy_times)
    print(f'poses: {args.poses}, noise {args.noise_mm} mm, best of {args.repeat}')
    print(f'dhcal fit (whole process): {td * 1000:9.1f} ms   RMS {dhcal_rms:.6f} mm')
    print(f'scipy least_squares (solve only): {ts * 1000:9.1f} ms   RMS {scipy_rms:.6f} mm '
          f'({sol.nfev} evaluations)')
    print(f'ratio scipy / dhcal: {ts / td:.1f}x')
    if abs(dhcal_rms - scipy_rms) > 1e-6 * max(1.0, scipy_rms) + 1e-6:
        print('FAIL: the two fits reach different RMS', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
