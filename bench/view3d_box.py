#!/usr/bin/env python3
"""view3d_box.py -- the View3D comparison scene of issue #17 (item 6).

A closed unit box, each of its six faces split into N x N quads, with a
0.3 m cube in its middle (faces as single quads): every row of the element
view-factor matrix sums to exactly 1, so max |row sum - 1| is a true error
measure.  Box faces face inward, cube faces outward.

    view3d_box.py N OUT.obj [OUT.vs3]

writes OUT.obj (+ OUT.mtl beside it): one named surface (`o`) per face,
each facet a separate polygon, so `--mesh-size` longer than a facet keeps
one element per facet: 6 N^2 + 6 elements (N = 30: 5,406; 20: 2,406;
60: 21,606).  With OUT.vs3, also the same case as View3D 3.2 input text
(Walton, NISTIR 6925, 2002): the box's facets as surfaces, the cube's faces
as obstruction-only surfaces (O), so the View3D figures of the issue can be
rerun on it.
"""
import os
import sys

CUBE_LO, CUBE_HI = 0.35, 0.65


def faces(n):
    """(name, [quad...]) per face; a quad is 4 corners counter-clockwise
    seen from the side its normal points to."""
    g = [k / n for k in range(n + 1)]
    out = []

    def grid(name, corner):
        quads = []
        for a in range(n):
            for b in range(n):
                quads.append([corner(g[a], g[b]), corner(g[a + 1], g[b]),
                              corner(g[a + 1], g[b + 1]), corner(g[a], g[b + 1])])
        out.append((name, quads))

    # Inward normals: floor z=0 (+z), ceiling z=1 (-z), x=0 (+x), x=1 (-x), y=0 (+y), y=1 (-y).
    grid("floor", lambda u, v: (u, v, 0.0))
    grid("ceiling", lambda u, v: (v, u, 1.0))
    grid("wall_x0", lambda u, v: (0.0, u, v))
    grid("wall_x1", lambda u, v: (1.0, v, u))
    grid("wall_y0", lambda u, v: (v, 0.0, u))
    grid("wall_y1", lambda u, v: (u, 1.0, v))
    return out


def cube():
    lo, hi = CUBE_LO, CUBE_HI
    # Outward normals, counter-clockwise seen from outside.
    return [
        ("cube_bottom", [[(lo, lo, lo), (lo, hi, lo), (hi, hi, lo), (hi, lo, lo)]]),
        ("cube_top", [[(lo, lo, hi), (hi, lo, hi), (hi, hi, hi), (lo, hi, hi)]]),
        ("cube_x0", [[(lo, lo, lo), (lo, lo, hi), (lo, hi, hi), (lo, hi, lo)]]),
        ("cube_x1", [[(hi, lo, lo), (hi, hi, lo), (hi, hi, hi), (hi, lo, hi)]]),
        ("cube_y0", [[(lo, lo, lo), (hi, lo, lo), (hi, lo, hi), (lo, lo, hi)]]),
        ("cube_y1", [[(lo, hi, lo), (lo, hi, hi), (hi, hi, hi), (hi, hi, lo)]]),
    ]


def fmt(x):
    return repr(round(x, 15))


def write_obj(path, surfaces):
    mtl = os.path.splitext(path)[0] + ".mtl"
    with open(mtl, "w") as f:
        f.write("newmtl grey\nKd 0.5 0.5 0.5\n")
    with open(path, "w") as f:
        f.write("# View3D box (bench/view3d_box.py): unit box, faces split, 0.3 m cube inside\n")
        f.write("mtllib %s\n" % os.path.basename(mtl))
        for name, quads in surfaces:
            f.write("o %s\nusemtl grey\n" % name)
            for q in quads:
                for p in q:
                    f.write("v %s %s %s\n" % tuple(fmt(c) for c in p))
                f.write("f -4 -3 -2 -1\n")


def write_vs3(path, box, obstr, n):
    """View3D 3.2 input: T title, C controls, F 3 (3-D), V vertices,
    S surfaces (#, v1..v4, base, cmb, emit, name), O obstruction-only
    surfaces (same fields, after all S lines)."""
    verts, index = [], {}

    def vid(p):
        if p not in index:
            verts.append(p)
            index[p] = len(verts)
        return index[p]

    surfs = []
    for name, quads in box:
        for k, q in enumerate(quads):
            surfs.append(([vid(p) for p in q], "%s_%d" % (name, k), False))
    for name, quads in obstr:
        surfs.append(([vid(p) for p in quads[0]], name, True))
    with open(path, "w") as f:
        f.write("T unit box, faces %d x %d, 0.3 m cube obstruction (bench/view3d_box.py)\n" % (n, n))
        # encl=0: the cube is obstruction-only, so the box's rows sum to what
        # the cube leaves them (about 0.82), not 1; encl=1 would make the .vf
        # smooth them to 1.
        f.write("C encl=0 list=0 eps=1.0e-4 maxU=8 maxO=8 minO=0 row=0 col=0\n")
        f.write("F 3\n")
        for k, p in enumerate(verts, 1):
            f.write("V %d %s %s %s\n" % (k, fmt(p[0]), fmt(p[1]), fmt(p[2])))
        for k, (v, name, obs) in enumerate(surfs, 1):
            f.write("%s %d %d %d %d %d 0 0 0.9 %s\n"
                    % ("O" if obs else "S", k, v[0], v[1], v[2], v[3], name))
        f.write("End of data\n")


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit("usage: view3d_box.py N OUT.obj [OUT.vs3]")
    n = int(sys.argv[1])
    if n < 1:
        sys.exit("view3d_box.py: N must be >= 1")
    box, obstr = faces(n), cube()
    write_obj(sys.argv[2], box + obstr)
    if len(sys.argv) == 4:
        write_vs3(sys.argv[3], box, obstr, n)


if __name__ == "__main__":
    main()
