#!/usr/bin/env python3
"""bench/control_variate.py -- the Monte Carlo solvers with and without
their control variate (B = beta + B', docs/methods.md), per surface against
gauss-seidel on the same mesh, over seeds.

    bench/control_variate.py [--binary PATH] [--seeds N] [--elements N]
                             [--scenes cornell,mixed,open,furnace]
                             [--solvers shooting,instant-radiosity]

Scenes: the built-in Cornell box (a lamp: beta = 0, so the control variate
changes nothing); `furnace`, the closed 1 x 2 x 3 m box of bench/furnace.py
(rho 0.8, E 0.5: B = 2.5); `mixed`, the same box with each face its own
reflectance (0.3 to 0.9) and E 0.5 everywhere (beta the weighted median,
a residual source left on five faces); `open`, the furnace box without its
top (z = 3): every element loses light through it, so the transport of
beta is estimated by rays.  For each solver, with (cv) and without (plain)
the control variate: `rms`, the relative error of every surface and channel
over all seeds; `bias`, the largest |mean over seeds| of a surface's error
with its standard error; the solve's seconds (control variate included).
"""
import argparse
import json
import math
import os
import subprocess
import tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)

CORNERS = [(0, 0, 0), (1, 0, 0), (1, 2, 0), (0, 2, 0), (0, 0, 3), (1, 0, 3), (1, 2, 3), (0, 2, 3)]
# faces wound inward (bench/furnace.py), named by the side they close
FACES = [('z0', (1, 2, 3, 4)), ('z1', (5, 8, 7, 6)), ('y0', (1, 5, 6, 2)), ('x1', (2, 6, 7, 3)),
         ('y1', (3, 7, 8, 4)), ('x0', (4, 8, 5, 1))]
MIXED_RHO = {'z0': 0.3, 'z1': 0.5, 'y0': 0.6, 'x1': 0.7, 'y1': 0.8, 'x0': 0.9}


def write_box(work, name, rho, skip=()):
    ke = 0.5 / math.pi
    obj = ['mtllib %s.mtl' % name] + ['v %g %g %g' % c for c in CORNERS]
    mtl = []
    for face, idx in FACES:
        if face in skip:
            continue
        mtl.append('newmtl m_%s\nKd %.17g %.17g %.17g\nKe %.17g %.17g %.17g\n' % ((face,) + (rho[face],) * 3 +
                                                                                   (ke,) * 3))
        obj += ['g %s' % face, 'usemtl m_%s' % face, 'f %d %d %d %d' % idx]
    open(os.path.join(work, name + '.obj'), 'w').write('\n'.join(obj) + '\n')
    open(os.path.join(work, name + '.mtl'), 'w').write('\n'.join(mtl))
    return os.path.join(work, name + '.obj')


def solve(binary, work, scene, options):
    stats = os.path.join(work, 's.json')
    cmd = [binary, 'render'] + ([scene] if scene else []) + ['-o', os.path.join(work, 'x.png'), '--width', '8',
                                                              '--height', '8', '-q', '--stats', stats] + options
    subprocess.run(cmd, check=True, capture_output=True)
    d = json.load(open(stats))
    return {s['name']: s['radiosity'] for s in d['surfaces']}, d['seconds']['solve'], d


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--binary', default=os.path.join(root, 'build', 'radiosity'))
    ap.add_argument('--seeds', type=int, default=8)
    ap.add_argument('--elements', type=int, default=2000)
    ap.add_argument('--scenes', default='cornell,furnace,mixed,open')
    ap.add_argument('--solvers', default='shooting,instant-radiosity')
    a = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix='radiosity-cv-') as work:
        scenes = {'cornell': '',
                  'furnace': write_box(work, 'furnace', {f: 0.8 for f, _ in FACES}),
                  'mixed': write_box(work, 'mixed', MIXED_RHO),
                  'open': write_box(work, 'open', {f: 0.8 for f, _ in FACES}, skip=('z1',))}
        mesh = ['--elements', str(a.elements)]
        for name in a.scenes.split(','):
            ref, _, _ = solve(a.binary, work, scenes[name], ['--solver', 'gauss-seidel', '--tolerance', '1e-9'] + mesh)
            print('%s: %d surfaces, gauss-seidel reference on %d elements' % (name, len(ref), a.elements))
            for solver in a.solvers.split(','):
                for cv in (False, True):
                    errors = {s: [] for s in ref}
                    seconds = 0.0
                    beta = None
                    for seed in range(a.seeds):
                        opts = ['--solver', solver, '--seed', str(seed)] + mesh + ([] if cv else ['--no-control-variate'])
                        got, t, d = solve(a.binary, work, scenes[name], opts)
                        seconds += t / a.seeds
                        c = d['solver'].get('control_variate')
                        if c:
                            beta = c['beta'][0] if c['groups_varied'] else 0.0
                        for s in ref:
                            for ch in range(3):
                                if ref[s][ch] > 0:
                                    errors[s].append((ch, got[s][ch] / ref[s][ch] - 1))
                    every = [e for s in errors for _, e in errors[s]]
                    rms = math.sqrt(sum(e * e for e in every) / len(every))
                    worst_bias, se = 0.0, 0.0
                    for s in errors:
                        for ch in range(3):
                            v = [e for c_, e in errors[s] if c_ == ch]
                            if not v:
                                continue
                            m = sum(v) / len(v)
                            sd = math.sqrt(sum((x - m) ** 2 for x in v) / max(len(v) - 1, 1))
                            if abs(m) >= abs(worst_bias):
                                worst_bias, se = m, sd / math.sqrt(len(v))
                    print('  %-18s %-5s rms %.2e  bias %+.1e (se %.1e)  %5.2f s%s' %
                          (solver, 'cv' if cv else 'plain', rms, worst_bias, se, seconds,
                           '' if beta is None else '  beta %.4g' % beta))


if __name__ == '__main__':
    main()
