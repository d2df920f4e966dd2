#!/usr/bin/env python3
"""bench/office_lit.py -- a lighting designer's run on a generated office:
`radiosity illuminance` with no solver options (hierarchical) against a
reference solver, side by side in one run.

    bench/office_lit.py [--rooms N] [--threads T] [--binary PATH]
                        [--reference "--solver gauss-seidel --elements 8000" | --no-reference]
                        [--paths N]

The office is `radiosity generate office --rooms N` (seed 0) with its
ceiling panels dark (Ke 0: a scene lit by luminaires), four downlights a
room (tests/data/luminaires/downlight.ies at 4,000 lm, 10 cm below the
ceiling at the room's quarter points) and a work-plane grid per room (the
floor's footprint at 0.8 m, EN 12464-1 spacing).  Prints, for each run,
the wall time and peak memory (/usr/bin/time), then per room Eavg of both
and their difference, and the share of points within 5% of the reference.
--no-reference runs the default alone (the 1,000-room office: its time,
memory and the solve's figures).  --paths N adds the converged reference
of bench/lux_reference.c (path tracing from each point, N paths, the
luminaires by next-event estimation; no elements or solver) and compares
both runs with it, per room and per point.  The working files stay in a temporary
folder, removed at the end.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)


def extents(obj_path):
    """Bounding boxes of the OBJ's objects (o name), from its vertices."""
    verts, box, cur = [], {}, None
    with open(obj_path) as f:
        for line in f:
            if line.startswith('v '):
                verts.append(tuple(map(float, line.split()[1:4])))
            elif line.startswith('o '):
                cur = line.split()[1]
            elif line.startswith('f ') and cur:
                b = box.setdefault(cur, [1e30, -1e30, 1e30, -1e30, 1e30, -1e30])
                for t in line.split()[1:]:
                    i = int(t.split('/')[0])
                    v = verts[i - 1 if i > 0 else i]
                    for a in range(3):
                        b[2 * a] = min(b[2 * a], v[a])
                        b[2 * a + 1] = max(b[2 * a + 1], v[a])
    return box


def run(cmd, log):
    timed = ['/usr/bin/time', '-f', '%e %M'] + cmd
    p = subprocess.run(timed, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit('failed: %s\n%s' % (' '.join(cmd), p.stderr))
    seconds, kb = p.stderr.strip().splitlines()[-1].split()
    print('%-12s %8.1f s %8.0f MB   %s' % (log, float(seconds), float(kb) / 1024, ' '.join(cmd[2:])))
    return float(seconds)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--rooms', type=int, default=10)
    ap.add_argument('--threads', type=int, default=2)
    ap.add_argument('--binary', default=os.path.join(root, 'build', 'radiosity'))
    ap.add_argument('--reference', default='--solver gauss-seidel --elements 8000')
    ap.add_argument('--no-reference', action='store_true')
    ap.add_argument('--paths', type=int, default=0)
    ap.add_argument('--tracer', default=os.path.join(root, 'build', 'bench', 'lux_reference'))
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix='radiosity-office-')
    try:
        obj = os.path.join(work, 'office.obj')
        subprocess.run([a.binary, 'generate', 'office', '--rooms', str(a.rooms), '-o', obj, '-q'], check=True)
        mtl = os.path.join(work, 'office.mtl')
        text = open(mtl).read()
        open(mtl, 'w').write(re.sub(r'(?m)^Ke .*$', 'Ke 0 0 0', text))
        shutil.copy(os.path.join(root, 'tests', 'data', 'luminaires', 'downlight.ies'), work)
        box = extents(obj)
        lums, grids = [], []
        for r in range(a.rooms):
            f, c = box['room%d/floor' % r], box['room%d/ceiling' % r]
            for k in range(4):
                x = f[0] + (f[1] - f[0]) * (0.75 if k % 2 else 0.25)
                z = f[4] + (f[5] - f[4]) * (0.75 if k // 2 else 0.25)
                lums.append({'file': 'downlight.ies', 'lumens': 4000,
                             'position': [round(x, 4), round(c[3] - 0.1, 4), round(z, 4)],
                             'name': 'room%d-%d' % (r, k)})
            grids.append({'name': 'room%d' % r, 'surface': 'room%d/floor' % r, 'height': 0.8, 'spacing': 'auto'})
        json.dump({'up': [0, 1, 0], 'luminaires': lums}, open(os.path.join(work, 'layout.json'), 'w'))
        json.dump({'up': 'y', 'grids': grids}, open(os.path.join(work, 'grids.json'), 'w'))
        base = [a.binary, 'illuminance', obj, '--luminaires', os.path.join(work, 'layout.json'),
                '--grid', os.path.join(work, 'grids.json'), '--threads', str(a.threads), '-q']
        print('office: %d rooms, %d downlights, %d threads' % (a.rooms, len(lums), a.threads))
        t_def = run(base + ['-o', os.path.join(work, 'd.json'), '--stats', os.path.join(work, 's.json')], 'default')
        st = json.load(open(os.path.join(work, 's.json')))
        h = st['solver'].get('hierarchical') or {}
        print('  default: %d leaves, %d links, solve %.1f s (refinement %.1f s), grids and writing %.1f s, %.0f lm landing of %.0f'
              % (h.get('leaves', 0), h.get('links', 0), st['seconds']['solve'], h.get('seconds_refine', 0.0),
                 t_def - st['seconds']['solve'] - st['seconds']['load'] - st['seconds']['mesh'],
                 st['luminaires']['direct_lumens'], st['luminaires']['lumens']))
        d = json.load(open(os.path.join(work, 'd.json')))['grids']
        if a.paths > 0:
            p = os.path.join(work, 'p.json')
            run([a.tracer, obj, '--luminaires', os.path.join(work, 'layout.json'), '--grid',
                 os.path.join(work, 'grids.json'), '--paths', str(a.paths), '--threads', str(a.threads),
                 '-o', p], 'paths')
            paths = json.load(open(p))['grids']
            print('  against the path-traced reference (%d paths a point; its standard error per room):' % a.paths)
            compare('default', d, paths)
        if a.no_reference:
            return
        t_ref = run(base + ['-o', os.path.join(work, 'r.json')] + a.reference.split(), 'reference')
        r = json.load(open(os.path.join(work, 'r.json')))['grids']
        if a.paths > 0:
            compare('reference', r, paths)
        print('  the default against the reference run:')
        compare('default', d, r)
        print('speed-up %.1fx' % (t_ref / t_def))
    finally:
        shutil.rmtree(work, ignore_errors=True)


def compare(label, d, r):
    """Per room Eavg of run d against r, the worst room and the points within 5%."""
    within, total, worst = 0, 0, 0.0
    for gd, gr in zip(d, r):
        diff = gd['E_avg_lux'] / gr['E_avg_lux'] - 1.0
        worst = max(worst, abs(diff))
        err = gr.get('E_avg_stderr_lux')
        print('  %-9s %-8s Eavg %8.1f lux  against %8.1f lux%s  %+6.2f%%' % (
            label, gd['name'], gd['E_avg_lux'], gr['E_avg_lux'], ' (+-%.2f)' % err if err else '', 100 * diff))
        for vd, vr in zip(gd['values'], gr['values']):
            ed = vd['E_lux'] if isinstance(vd, dict) else vd
            er = vr['E_lux'] if isinstance(vr, dict) else vr
            total += 1
            within += abs(ed - er) <= 0.05 * abs(er)
    print('  %s: worst room Eavg %.2f%%; points within 5%%: %d of %d (%.1f%%)' %
          (label, 100 * worst, within, total, 100.0 * within / max(total, 1)))


if __name__ == '__main__':
    main()
