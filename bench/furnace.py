#!/usr/bin/env python3
"""bench/furnace.py -- the closed furnace for every solver and form-factor
method at its defaults.

    bench/furnace.py [--binary PATH] [--solvers a,b,...] [--form-factors a,b,...]

The scene: a closed 1 x 2 x 3 m box, faces wound inward, every face
reflectance 0.8 and emitting 0.5 W/m^2 (Ke = 0.5 / pi): B = E / (1 - rho) =
2.5 everywhere, and what the box absorbs equals what it emits (11 W).
Prints, per run, the surface's mean B, its relative error, absorbed /
emitted - 1, the elements and the solve's seconds (form factors included).
"""
import argparse
import json
import math
import os
import subprocess
import tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)

SOLVERS = ('gauss-seidel southwell jacobi direct conjugate-gradient shooting hierarchical galerkin-linear '
           'galerkin-constant collocation instant-radiosity instant-radiosity-clamped')
FORM_FACTORS = 'analytic hemicube hemisphere montecarlo contour hybrid'

BOX = """mtllib box.mtl
v 0 0 0
v 1 0 0
v 1 2 0
v 0 2 0
v 0 0 3
v 1 0 3
v 1 2 3
v 0 2 3
usemtl m
f 1 2 3 4
f 5 8 7 6
f 1 5 6 2
f 2 6 7 3
f 3 7 8 4
f 4 8 5 1
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--binary', default=os.path.join(root, 'build', 'radiosity'))
    ap.add_argument('--solvers', default=','.join(SOLVERS.split()))
    ap.add_argument('--form-factors', default=','.join(FORM_FACTORS.split()))
    a = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix='radiosity-furnace-') as work:
        open(os.path.join(work, 'box.obj'), 'w').write(BOX)
        ke = 0.5 / math.pi
        open(os.path.join(work, 'box.mtl'), 'w').write('newmtl m\nKd 0.8 0.8 0.8\nKe %.17g %.17g %.17g\n' % (ke, ke, ke))
        runs = [['--solver', s] for s in a.solvers.split(',') if s]
        runs += [['--solver', 'gauss-seidel', '--form-factors', f] for f in a.form_factors.split(',') if f]
        stats = os.path.join(work, 's.json')
        for r in runs:
            cmd = [a.binary, 'render', os.path.join(work, 'box.obj'), '-o', os.path.join(work, 'x.png'),
                   '--width', '16', '--height', '16', '-q', '--stats', stats] + r
            p = subprocess.run(cmd, capture_output=True, text=True)
            label = ' '.join(r)
            if p.returncode != 0:
                print('%-48s failed: %s' % (label, p.stderr.strip()[:200]))
                continue
            d = json.load(open(stats))
            B = d['surfaces'][0]['radiosity'][0]
            pw = d['power_W']
            print('%-48s B %.6f  error %+.1e  power %+.1e  %5d elements  %5.1f s' %
                  (label, B, B / 2.5 - 1, pw['absorbed'] / pw['emitted'] - 1, d['elements'],
                   d['seconds']['solve'] + d['seconds']['form_factors']))


if __name__ == '__main__':
    main()
