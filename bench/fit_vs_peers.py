#!/usr/bin/env python3
"""dhcal fit against its peers on the same problem, timed in one run.

Problem: the paper's 6-DOF arm (nominal Table 2, actual Table 1 with every joint offset
2 deg), N tool positions with Gaussian noise (0.02 mm per coordinate), for N = 2000, 20 000
and 200 000 rows. The generated model JSON and measurement CSV are the input of every peer
that runs as a program:

- `dhcal fit --json`, as a whole process (start-up, parsing the files, fitting, its
  diagnostics, printing JSON);
- the Ceres peer bench/ceres_fit.cc (build/bench-ceres/ceres_fit), as a whole process, in
  three variants: ceres::Solve with Levenberg-Marquardt and DENSE_NORMAL_CHOLESKY, the same
  with DENSE_QR, and ceres::TinySolver; analytic Jacobian, one thread. It also reports its
  solver call's time alone;
- scipy.optimize.least_squares on vectorised numpy forward kinematics with the same
  parameters: its solver call only (no interpreter start-up, no file parsing), which favours
  scipy. It is skipped above --scipy-max-rows (slow), and the table says so.

All fit the parameters dhcal fits by default (the Ceres peer chooses them by dhcal's rules;
the benchmark checks that the names agree, and gives scipy dhcal's list), with the residual
predicted - measured tool point, so their RMS must agree. The programs run round-robin,
--repeat times each, so that a change of a shared machine's load hits all alike; times are
the best run's, wall clock (the ratio: peer time / dhcal time, below 1 the peer is faster)
and CPU (user + system, less sensitive to neighbours). Peak memory is each process's
maximum resident set size, from GNU time in one more run.

Usage: fit_vs_peers.py --dhcal build/host/tools/dhcal --ceres build/bench-ceres/ceres_fit
                       [--rows 2000,20000,200000] [--repeat 5] [--noise-mm 0.02]
                       [--scipy-max-rows 20000] [--rms-tolerance 0.02]
Exit status 1 when a program fails, when the parameter sets differ, or when an RMS differs
from dhcal's by more than --rms-tolerance (relative). The issue's speed goals are printed
as met or not met; they do not change the exit status.
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
SEED = 20261121
GNU_TIME = '/usr/bin/time'  # Debian's package time (scripts/packages, need bench)
DEG = np.pi / 180.0


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


# dhcal's parameter names -> (index into fk_points' parameter lists, joint)
KINDS = {'theta': 0, 'd': 1, 'a': 2, 'alpha': 3, 'beta': 4}


def split_name(name):
    kind = name.rstrip('0123456789')
    return KINDS[kind], int(name[len(kind):]) - 1


def unpack(p, names, nominal):
    params = [np.array(v, dtype=float) for v in nominal]
    for value, name in zip(p, names):
        kind, joint = split_name(name)
        params[kind][joint] += value
    return params


def generate(rows, noise_mm):
    rng = np.random.default_rng(SEED)
    truth = ([2.0 * DEG] * 6, [r[2] for r in TABLE1], [r[1] for r in TABLE1],
             [r[0] * DEG for r in TABLE1], [0.0] * 6)
    q = rng.uniform(-np.pi, np.pi, size=(rows, 6))
    meas = fk_points(q, *truth) + rng.normal(0.0, noise_mm, size=(rows, 3))
    return q, meas


def write_files(directory, q, meas):
    model = {"name": "paper-6dof", "joints": [
        {"alpha_deg": r[0], "a_mm": r[1], "d_mm": r[2], "theta_offset_deg": 0,
         "min_deg": -180, "max_deg": 180} for r in TABLE2]}
    model_path = os.path.join(directory, 'model.json')
    data_path = os.path.join(directory, 'data.csv')
    with open(model_path, 'w') as f:
        json.dump(model, f)
    table = np.hstack([q / DEG, meas])
    with open(data_path, 'w') as f:
        f.write('q1,q2,q3,q4,q5,q6,x,y,z\n')
        np.savetxt(f, table, fmt=['%.12f'] * 6 + ['%.9f'] * 3, delimiter=',')
    return model_path, data_path


def run_process(cmd, directory):
    """Runs cmd once, output to files: (wall s, CPU s (user + system), exit code, stdout,
    stderr)."""
    out_path = os.path.join(directory, 'stdout')
    err_path = os.path.join(directory, 'stderr')
    with open(out_path, 'w') as out, open(err_path, 'w') as err:
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=out, stderr=err)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    with open(out_path) as out, open(err_path) as err:
        return (wall, usage.ru_utime + usage.ru_stime, proc.returncode, out.read(),
                err.read())


def peak_rss_kib(cmd, directory, label):
    """Peak RSS of one run under GNU time. (A child of this interpreter cannot report its
    own: Linux charges it the interpreter's memory, which it shared until its exec.)"""
    _, _, code, _, err = run_process([GNU_TIME, '-f', 'peak_rss_kib %M', *cmd], directory)
    last = err.strip().splitlines()[-1] if err.strip() else ''
    if code != 0 or not last.startswith('peak_rss_kib '):
        raise RuntimeError(f'{label} under {GNU_TIME} exited with {code}: {err.strip()[:400]}')
    return int(last.split()[1])


def best_of(repeat, programs, directory):
    """Runs every program of programs ({key: (label, cmd)}) repeat times, round-robin, so
    that a change of the machine's load hits all alike. Returns {key: (best wall s, best
    CPU s, peak RSS KiB, [JSON output of every run])}."""
    walls = {k: [] for k in programs}
    cpus = {k: [] for k in programs}
    results = {k: [] for k in programs}
    for _ in range(repeat):
        for key, (label, cmd) in programs.items():
            wall, cpu, code, out, err = run_process(cmd, directory)
            if code != 0:
                raise RuntimeError(f'{label} exited with {code}: {err.strip()[:400]}')
            walls[key].append(wall)
            cpus[key].append(cpu)
            results[key].append(json.loads(out))
    return {k: (min(walls[k]), min(cpus[k]), peak_rss_kib(cmd, directory, label), results[k])
            for k, (label, cmd) in programs.items()}


def scipy_fit(q, meas, names, repeat):
    nominal = ([0.0] * 6, [r[2] for r in TABLE2], [r[1] for r in TABLE2],
               [r[0] * DEG for r in TABLE2], [0.0] * 6)
    # dhcal's names are in deg and mm; scipy works in rad and mm.
    def residuals(p):
        return (fk_points(q, *unpack(p, names, nominal)) - meas).ravel()

    times, cpus = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        sol = least_squares(residuals, np.zeros(len(names)), x_scale='jac')
        times.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    r = sol.fun.reshape(-1, 3)
    rms = float(np.sqrt(np.mean(np.sum(r * r, axis=1))))
    return min(times), min(cpus), rms, sol.nfev, sol.njev


def fmt_ms(seconds):
    return f'{seconds * 1000:.1f}' if seconds is not None else '-'


def run_case(args, rows, tmp):
    """Measures one row count; returns (table lines, failures, times by solver)."""
    q, meas = generate(rows, args.noise_mm)
    directory = os.path.join(tmp, f'rows-{rows}')
    os.mkdir(directory)
    model_path, data_path = write_files(directory, q, meas)
    files = ['--model', model_path, '--data', data_path]
    failures = []

    ceres = (('solve', 'Ceres Solve, DENSE_NORMAL_CHOLESKY'),
             ('solve-qr', 'Ceres Solve, DENSE_QR'),
             ('tiny', 'Ceres TinySolver'))
    programs = {'dhcal': ('dhcal fit', [args.dhcal, 'fit', *files, '--json'])}
    for solver, label in ceres:
        programs[solver] = (label, [args.ceres, *files, '--solver', solver])
    measured = best_of(args.repeat, programs, directory)

    t_dhcal, cpu, rss, runs = measured['dhcal']
    dhcal = runs[-1]
    names = [p['name'] for p in dhcal['parameters']]
    lines = [{'solver': 'dhcal fit', 'time': t_dhcal, 'cpu': cpu, 'solve': None,
              'iters': dhcal['iterations'], 'rms': dhcal['rms_mm'], 'rss': rss}]
    times = {'dhcal': t_dhcal}
    if dhcal['outliers']:
        failures.append(f'{rows} rows: dhcal left {len(dhcal["outliers"])} rows out as '
                        'outliers: its RMS is over fewer rows than the peers\'')

    for solver, label in ceres:
        t, cpu, rss, runs = measured[solver]
        res = runs[-1]
        ceres_names = [p['name'] for p in res['parameters']]
        if ceres_names != names:
            failures.append(f'{rows} rows: {label} fits {ceres_names}, dhcal fits {names}: '
                            'not the same problem')
        solve = min(r['solve_ms'] for r in runs) / 1000.0
        lines.append({'solver': label, 'time': t, 'cpu': cpu, 'solve': solve,
                      'iters': res['iterations'], 'rms': res['rms_mm'], 'rss': rss})
        times[solver] = t

    if rows <= args.scipy_max_rows:
        t, cpu, rms, nfev, njev = scipy_fit(q, meas, names, args.repeat)
        lines.append({'solver': 'scipy least_squares (solve only)', 'time': t, 'cpu': cpu,
                      'solve': t,
                      'iters': f'{njev} J, {nfev} f', 'rms': rms, 'rss': None})
        times['scipy'] = t
    else:
        lines.append({'solver': f'scipy least_squares: skipped, {rows} rows > '
                                f'--scipy-max-rows {args.scipy_max_rows}', 'time': None})

    out = []
    for ln in lines:
        if ln['time'] is None:
            out.append(f'{rows:>7d}  {ln["solver"]}')
            continue
        ratio = ln['time'] / t_dhcal
        rss = f'{ln["rss"] / 1024:.1f}' if ln['rss'] is not None else '-'
        out.append(f'{rows:>7d}  {ln["solver"]:36s} {fmt_ms(ln["time"]):>9s} {ratio:9.2f}x '
                   f'{fmt_ms(ln["cpu"]):>8s} {fmt_ms(ln["solve"]):>9s} {str(ln["iters"]):>12s} '
                   f'{ln["rms"]:10.6f} {rss:>8s}')
        if abs(ln['rms'] - dhcal['rms_mm']) > args.rms_tolerance * dhcal['rms_mm']:
            rel = abs(ln['rms'] - dhcal['rms_mm']) / dhcal['rms_mm']
            failures.append(f'{rows} rows: {ln["solver"]} reaches RMS {ln["rms"]:.9f} mm, '
                            f'dhcal {dhcal["rms_mm"]:.9f} mm: {rel * 100:.3g} % apart, more '
                            f'than {args.rms_tolerance * 100:g} %')
    return out, failures, times


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--dhcal', required=True)
    ap.add_argument('--ceres', required=True)
    ap.add_argument('--rows', default='2000,20000,200000')
    ap.add_argument('--noise-mm', type=float, default=0.02)
    ap.add_argument('--repeat', type=int, default=5)
    ap.add_argument('--scipy-max-rows', type=int, default=20000)
    ap.add_argument('--rms-tolerance', type=float, default=0.02)
    args = ap.parse_args()
    row_counts = [int(r) for r in args.rows.split(',')]

    failures = []
    goals = []
    print(f'dhcal fit and its peers: paper 6-DOF, noise {args.noise_mm} mm, best of '
          f'{args.repeat} (programs run round-robin); whole processes except scipy (solve '
          'only); peer/dhcal is the wall-time ratio; CPU = user + system')
    print(f'{"rows":>7s}  {"solver":36s} {"time ms":>9s} {"peer/dhcal":>10s} {"CPU ms":>8s} '
          f'{"solve ms":>9s} {"iterations":>12s} {"RMS mm":>10s} {"peak MB":>8s}', flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        for rows in row_counts:
            try:
                out, fails, times = run_case(args, rows, tmp)
            except (RuntimeError, ValueError, KeyError) as e:
                print(f'{rows} rows: FAIL: {e}')
                failures.append(f'{rows} rows: {e}')
                continue
            print('\n'.join(out), flush=True)
            failures += fails
            t = times['dhcal']
            if rows == 2000:
                goals.append(('dhcal fit at least 2x faster than Ceres Solve (2000 rows)',
                              times['solve'] / t >= 2.0,
                              f'Ceres Solve / dhcal = {times["solve"] / t:.2f}'))
                goals.append(('dhcal fit faster than TinySolver (2000 rows)',
                              times['tiny'] / t > 1.0,
                              f'TinySolver / dhcal = {times["tiny"] / t:.2f}'))
                if 'scipy' in times:
                    goals.append(('dhcal fit at least 30x faster than scipy (2000 rows)',
                                  times['scipy'] / t >= 30.0,
                                  f'scipy / dhcal = {times["scipy"] / t:.1f}'))
            if rows == 200000:
                goals.append(('200000 rows fitted in under 1 s', t < 1.0,
                              f'dhcal fit {t * 1000:.0f} ms'))

    print()
    for text, met, detail in goals:
        print(f'goal: {text}: {"met" if met else "not met"} ({detail})')
    for f in failures:
        print(f'FAIL: {f}', file=sys.stderr)
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
