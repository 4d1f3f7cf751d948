#!/usr/bin/env python3
"""Units and frames before any fit (docs/cli.md, 1.11): data written in metres, angles in
radians, two joint columns or two measured columns exchanged are refused with exit 2 and
the cause named, by every command that reads them (compare, fit, diagnose, refine, plot,
compensate; plan for a model or a --min-z in metres); the files as they are pass (exit 0)
in every command; --no-units-check lets the converted files through. Points in another
frame than the model's base are refused by the commands that fit unless --effects has
base_frame, and only noted by compare.

Usage: test_units.py --dhcal PATH --scratch DIR [--realdata DIR]
  Without --realdata: the repository's examples (examples/data/compliance: positions, and
  the same rows as the wire lengths of its model's measurer, computed here). With
  --realdata: the real arms measured by others (UR5, WAM and UR10-D converted; every set's
  files as they are, UR10 A..D included); exit 77 with the reason when the folder is absent.
The converted copies are written to --scratch (the build tree), never the repository.
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
EXAMPLE = os.path.join(ROOT, 'examples', 'data', 'compliance')
SKIP = 77

FAILURES = []


def check(ok, what):
    what = ' '.join(what.split())  # the program's messages on one line
    print(('ok      ' if ok else 'FAILED  ') + what, flush=True)
    if not ok:
        FAILURES.append(what)


# ---------------------------------------------------------------- CSV files

def read_csv(path):
    """(header, rows of floats); comment lines dropped."""
    with open(path) as f:
        lines = [l.strip() for l in f if l.strip() and not l.lstrip().startswith('#')]
    header = [h.strip() for h in lines[0].split(',')]
    return header, [[float(v) for v in l.split(',')] for l in lines[1:]]


def write_csv(path, header, rows):
    with open(path, 'w') as f:
        f.write(','.join(header) + '\n')
        for r in rows:
            f.write(','.join(repr(v) for v in r) + '\n')


def joint_columns(header):
    return [k for k, h in enumerate(header) if h[0] == 'q' and h[1:].isdigit()]


def converted(header, rows, how):
    """A copy of rows with one mistake a user makes (or, 'frame', another frame)."""
    col = {h: k for k, h in enumerate(header)}
    meas = [col[c] for c in ('x', 'y', 'z', 'L1', 'L2', 'L3') if c in col]
    out = [list(r) for r in rows]
    for r in out:
        if how == 'metres':
            for k in meas:
                r[k] /= 1000.0
        elif how == 'radians':
            for k in joint_columns(header):
                r[k] = math.radians(r[k])
        elif how == 'swap_q2q3':
            r[col['q2']], r[col['q3']] = r[col['q3']], r[col['q2']]
        elif how == 'swap_xy':
            a, b = ('x', 'y') if 'x' in col else ('L1', 'L2')
            r[col[a]], r[col[b]] = r[col[b]], r[col[a]]
        elif how == 'frame':  # a tracker's frame: turned 35 deg about z, moved 1.7 m
            c, s = math.cos(math.radians(35.0)), math.sin(math.radians(35.0))
            x, y = r[col['x']], r[col['y']]
            r[col['x']], r[col['y']] = c * x - s * y + 1500.0, s * x + c * y - 800.0
            r[col['z']] += 300.0
    return out


def cause_of(how, wires):
    measured = 'wire lengths' if wires else 'positions'
    pair = 'L1 and L2' if wires else 'x and y'
    return {'metres': f'{measured} look like metres',
            'radians': 'joint angles look like radians',
            'swap_q2q3': 'columns q2 and q3 look swapped',
            'swap_xy': f'columns {pair} look swapped',
            'frame': "another frame than the model's base"}[how]


def wire_rows(model_path, header, rows):
    """The rows' tool points as the wire lengths of the model's measurer, computed here:
    anchor k in the world is T_meas * anchor_k (frame rpy: R = Rz(yaw) Ry(pitch) Rx(roll))."""
    with open(model_path) as f:
        m = json.load(f)['measurer']
    r_, p_, y_ = (math.radians(v) for v in m['frame']['rpy_deg'])
    cr, sr, cp, sp, cy, sy = (math.cos(r_), math.sin(r_), math.cos(p_), math.sin(p_),
                              math.cos(y_), math.sin(y_))
    rot = [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
           [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
           [-sp, cp * sr, cp * cr]]
    t = m['frame']['xyz_mm']
    anchors = [[sum(rot[i][k] * a[k] for k in range(3)) + t[i] for i in range(3)]
               for a in m['anchors_mm']]
    col = {h: k for k, h in enumerate(header)}
    keep = [k for k, h in enumerate(header) if h not in ('x', 'y', 'z')]
    out = []
    for r in rows:
        p = [r[col['x']], r[col['y']], r[col['z']]]
        out.append([r[k] for k in keep] + [math.dist(p, a) for a in anchors])
    return [header[k] for k in keep] + ['L1', 'L2', 'L3'], out


# ---------------------------------------------------------------- the program

class Runner:
    def __init__(self, dhcal, scratch):
        self.dhcal = dhcal
        self.scratch = scratch

    def run(self, *args):
        return subprocess.run([self.dhcal, *args], capture_output=True, text=True,
                              errors='replace', timeout=900)

    def data_command(self, command, model, data, effects=None, extra=(), out=None):
        args = [command, '--model', model, '--data', data]
        if effects:
            args += ['--effects', effects]
        if command == 'plot':
            args += ['--out', out or os.path.join(self.scratch, 'plot')]
        elif out is not None and command in ('fit', 'refine'):
            args += ['--out', out]
        return self.run(*args, *extra)


def refused(result, path, cause):
    """Exit 2, one message naming the file and the cause and how to go on."""
    lines = [l for l in result.stderr.splitlines() if l.startswith('dhcal: ')]
    return (result.returncode == 2 and len(lines) == 1 and lines[0].startswith(f'dhcal: {path}: ')
            and cause in lines[0] and 'use --no-units-check if they are right' in lines[0])


def passed(result):
    return result.returncode == 0 and 'look like' not in result.stderr \
        and 'another frame' not in result.stderr


def let_through(result):
    """--no-units-check: no refusal; the computation may still fail on such data (exit 1)."""
    return result.returncode in (0, 1) and 'look like' not in result.stderr


COMMANDS = ('compare', 'fit', 'diagnose', 'refine', 'plot')
MISTAKES = ('metres', 'radians', 'swap_q2q3', 'swap_xy')


def check_set(run, name, model, data, effects, through_commands, heldout=None):
    """Every command on the file as it is and on its converted copies."""
    header, rows = read_csv(data)
    wires = 'L1' in header
    for command in COMMANDS:
        r = run.data_command(command, model, data, effects)
        check(passed(r), f'{name}: {command} on the file as it is: exit 0 '
                         f'(got {r.returncode}: {r.stderr.strip()[:300]})')
    if heldout is not None:
        r = run.data_command('fit', model, data, effects, ('--heldout', heldout))
        check(passed(r), f'{name}: fit with its held-out rows: exit 0 (got {r.returncode})')
    r = run.data_command('compare', model, data)
    check(passed(r) and r.stderr == '', f'{name}: compare without effects: no note '
                                        f'({r.stderr.strip()[:300]})')
    for how in MISTAKES:
        path = os.path.join(run.scratch, f'{name}-{how}.csv')
        write_csv(path, header, converted(header, rows, how))
        cause = cause_of(how, wires)
        for command in COMMANDS:
            out = os.path.join(run.scratch, f'{name}-{how}-{command}.out')
            r = run.data_command(command, model, path, effects, out=out)
            check(refused(r, path, cause) and not os.path.exists(out),
                  f'{name} {how}: {command} exits 2 naming "{cause}", nothing written '
                  f'(got {r.returncode}: {r.stderr.strip()[:400]})')
        for command in through_commands:
            r = run.data_command(command, model, path, effects, ('--no-units-check',))
            check(let_through(r), f'{name} {how}: {command} --no-units-check goes on '
                                  f'(got {r.returncode}: {r.stderr.strip()[:200]})')
        print(f'        {name} {how}: {refusal_text(run, model, path, effects)}')
        if heldout is not None and how == 'metres':
            r = run.data_command('fit', model, data, effects, ('--heldout', path))
            check(refused(r, path, cause), f'{name}: held-out rows in metres are refused')
    if not wires:
        check_frame(run, name, model, header, rows)


def refusal_text(run, model, path, effects):
    r = run.data_command('compare', model, path, effects)
    return r.stderr.strip()[len('dhcal: '):]


def check_frame(run, name, model, header, rows):
    """Another frame: the fits refuse it without base_frame and take it with base_frame;
    compare notes it and exits 0."""
    path = os.path.join(run.scratch, f'{name}-frame.csv')
    write_csv(path, header, converted(header, rows, 'frame'))
    cause = cause_of('frame', False)
    r = run.data_command('fit', model, path, 'tool_offset')
    check(refused(r, path, cause) and '--effects base_frame' in r.stderr,
          f'{name} frame: fit without base_frame exits 2 naming "{cause}" '
          f'(got {r.returncode}: {r.stderr.strip()[:400]})')
    print(f'        {name} frame: {r.stderr.strip()[len("dhcal: "):]}')
    r = run.data_command('compare', model, path)
    check(r.returncode == 0 and 'dhcal: note: ' in r.stderr and cause in r.stderr,
          f'{name} frame: compare exits 0 with a note (got {r.returncode}: {r.stderr[:200]})')
    r = run.data_command('fit', model, path, 'base_frame,tool_offset')
    check(r.returncode == 0 and 'another frame' not in r.stderr,
          f'{name} frame: fit with base_frame goes on (got {r.returncode}: {r.stderr[:200]})')


# ---------------------------------------------------------------- plan and compensate

def scaled_model(model, path, factor):
    with open(model) as f:
        m = json.load(f)
    for j in m['joints']:
        j['a_mm'] *= factor
        j['d_mm'] *= factor
    m['tool_mm'] = [v * factor for v in m.get('tool_mm', [0.0, 0.0, 0.0])]
    if 'base' in m and 'xyz_mm' in m['base']:
        m['base']['xyz_mm'] = [v * factor for v in m['base']['xyz_mm']]
    if 'measurer' in m:
        m['measurer']['anchors_mm'] = [[v * factor for v in a] for a in m['measurer']['anchors_mm']]
        fr = m['measurer'].get('frame', {})
        if 'xyz_mm' in fr:
            fr['xyz_mm'] = [v * factor for v in fr['xyz_mm']]
    with open(path, 'w') as f:
        json.dump(m, f)


def check_plan(run, name, model):
    out = os.path.join(run.scratch, f'{name}-plan.csv')
    base = ('plan', '--poses', '8', '--candidates', '200', '--end-candidates', '0')
    r = run.run(*base, '--model', model, '--out', out)
    check(r.returncode == 0, f'{name}: plan on the model as it is: exit 0 ({r.stderr[:200]})')
    metres = os.path.join(run.scratch, f'{name}-model-metres.json')
    scaled_model(model, metres, 0.001)
    os.remove(out)
    r = run.run(*base, '--model', metres, '--out', out)
    check(r.returncode == 2 and f"{metres}: the model's lengths look like metres" in r.stderr
          and not os.path.exists(out),
          f'{name}: plan of a model in metres exits 2, nothing written ({r.stderr[:300]})')
    print(f'        {name} plan: {r.stderr.strip()}')
    r = run.run(*base, '--model', metres, '--out', out, '--no-units-check')
    check(r.returncode != 2, f'{name}: plan --no-units-check goes on (got {r.returncode})')
    if os.path.exists(out):
        os.remove(out)
    r = run.run(*base, '--model', model, '--min-z', '0.2', '--out', out)
    check(r.returncode == 2 and '--min-z 0.2 looks like metres' in r.stderr
          and not os.path.exists(out), f'{name}: plan --min-z 0.2 exits 2 ({r.stderr[:300]})')
    r = run.run(*base, '--model', model, '--min-z', '0.2', '--out', out, '--no-units-check')
    check(r.returncode == 0, f'{name}: plan --min-z 0.2 --no-units-check goes on')
    for cmd, m in (('fit', metres), ('compare', metres)):
        r = run.data_command(cmd, m, os.path.join(run.scratch, f'{name}-targets.csv'))
        check(r.returncode == 2 and "the model's lengths look like metres" in r.stderr,
              f'{name}: {cmd} with a model in metres exits 2 ({r.stderr[:300]})')


def check_compensate(run, name, model, data, rows_wanted=20):
    """Targets: measured points with their angles as the start (today's commands)."""
    header, rows = read_csv(data)
    col = {h: k for k, h in enumerate(header)}
    keep = joint_columns(header) + [col['x'], col['y'], col['z']]
    t_header = [header[k] for k in keep]
    t_rows = [[r[k] for k in keep] for r in rows[:: max(1, len(rows) // rows_wanted)][:rows_wanted]]
    targets = os.path.join(run.scratch, f'{name}-targets.csv')
    write_csv(targets, t_header, t_rows)
    out = os.path.join(run.scratch, f'{name}-joints.csv')
    r = run.run('compensate', '--model', model, '--targets', targets, '--out', out)
    check(r.returncode == 0 and 'look like' not in r.stderr,
          f'{name}: compensate on the targets as they are: exit 0 ({r.stderr[:300]})')
    os.remove(out)
    for how in MISTAKES:
        path = os.path.join(run.scratch, f'{name}-targets-{how}.csv')
        write_csv(path, t_header, converted(t_header, t_rows, how))
        cause = cause_of(how, False)
        r = run.run('compensate', '--model', model, '--targets', path, '--out', out)
        check(refused(r, path, cause) and not os.path.exists(out),
              f'{name} {how}: compensate exits 2 naming "{cause}", nothing written '
              f'(got {r.returncode}: {r.stderr.strip()[:400]})')
        r = run.run('compensate', '--model', model, '--targets', path, '--out', out,
                    '--no-units-check')
        check(let_through(r), f'{name} {how}: compensate --no-units-check goes on '
                              f'(got {r.returncode})')
        if os.path.exists(out):
            os.remove(out)
    # targets without start angles: only where they lie
    xyz = os.path.join(run.scratch, f'{name}-targets-xyz-metres.csv')
    write_csv(xyz, ['x', 'y', 'z'], [[v / 1000.0 for v in r[-3:]] for r in t_rows])
    r = run.run('compensate', '--model', model, '--targets', xyz, '--out', out)
    check(refused(r, xyz, 'targets look like metres'),
          f'{name}: compensate of angle-less targets in metres exits 2 ({r.stderr[:300]})')
    metres = os.path.join(run.scratch, f'{name}-model-metres.json')
    scaled_model(model, metres, 0.001)
    r = run.run('compensate', '--model', metres, '--targets', targets, '--out', out)
    check(r.returncode == 2 and "the model's lengths look like metres" in r.stderr,
          f'{name}: compensate with a model in metres exits 2 ({r.stderr[:300]})')


# ---------------------------------------------------------------- the two parts

def examples(run):
    model = os.path.join(EXAMPLE, 'model.json')
    data = os.path.join(EXAMPLE, 'train.csv')
    check_set(run, 'compliance', model, data, None, COMMANDS,
              heldout=os.path.join(EXAMPLE, 'heldout.csv'))
    header, rows = read_csv(data)
    w_header, w_rows = wire_rows(model, header, rows)
    wires = os.path.join(run.scratch, 'compliance-wires.csv')
    write_csv(wires, w_header, w_rows)
    check_set(run, 'compliance-wires', model, wires, None, ('compare', 'fit'))
    check_compensate(run, 'compliance', model, data)
    check_plan(run, 'compliance', model)


CONVERTED = ('ur5-jacobi', 'wam-jacobi', 'ur10-ipa-d')


def realdata(run, folder):
    for name in CONVERTED:
        model = os.path.join(folder, name, 'model.json')
        data = os.path.join(folder, name, 'data.csv')
        held = os.path.join(folder, name, 'heldout.csv')
        check_set(run, name, model, data, 'base_frame,tool_offset', ('compare', 'fit'),
                  heldout=held if os.path.exists(held) else None)
        check_compensate(run, name, model, data)
        check_plan(run, name, model)
    # every other set as it is: no false alarm (the check is the same in every command)
    for name in sorted(os.listdir(folder)):
        data = os.path.join(folder, name, 'data.csv')
        model = os.path.join(folder, name, 'model.json')
        if name in CONVERTED or not (os.path.exists(data) and os.path.exists(model)):
            continue
        r = run.data_command('compare', model, data)
        check(r.returncode == 0 and r.stderr == '',
              f'{name}: compare on the file as it is: exit 0, no note ({r.stderr[:300]})')
        r = run.data_command('fit', model, data, 'base_frame,tool_offset')
        check(passed(r), f'{name}: fit on the file as it is: exit 0 '
                         f'(got {r.returncode}: {r.stderr[:300]})')


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--dhcal', required=True)
    ap.add_argument('--scratch', required=True)
    ap.add_argument('--realdata')
    a = ap.parse_args()
    if a.realdata is not None and not os.path.isdir(a.realdata):
        print(f'skipped: no real data at {a.realdata} (set DHCAL_REALDATA_DIR to the folder '
              'of the UR5, WAM and UR10 sets)')
        return SKIP
    shutil.rmtree(a.scratch, ignore_errors=True)
    os.makedirs(a.scratch)
    run = Runner(a.dhcal, a.scratch)
    if a.realdata is None:
        examples(run)
    else:
        realdata(run, a.realdata)
    if FAILURES:
        print(f'{len(FAILURES)} checks failed')
        return 1
    print('all checks passed')
    return 0


if __name__ == '__main__':
    sys.exit(main())
