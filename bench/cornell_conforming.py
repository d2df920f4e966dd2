#!/usr/bin/python3
"""The Cornell box with its floor split along the blocks' footprints.

    /usr/bin/python3 bench/cornell_conforming.py tests/data/cornell_box.obj OUT.obj

Writes OUT.obj (and beside it, a copy of the MTL) as the input box, except
that the surface `floor` is made of convex polygons that follow the contact
lines: the floor minus each block's footprint (the block's vertices at
y = 0), cut edge by edge, and the footprints themselves.  The surface keeps
its name and its whole area, so its mean is the same quantity as the
built-in box's; but no element then straddles a contact line, and a
uniform mesh converges on it as on the walls (a mesh that does not conform
leaves each straddling element half lit, half dark: an error of order h
whose sign flips with where the grid falls, which makes a sequence of
meshes useless for extrapolation).  bench/cornell_reference.sh uses it.
"""
import math
import os
import shutil
import sys


def area2(poly):
    """Twice the signed area in the (x, z) plane."""
    return sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(poly, poly[1:] + poly[:1]))


def side(a, b, p, sign):
    return sign * ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]))


def clip(poly, a, b, sign, keep_inside):
    """Sutherland-Hodgman: the part of convex poly on one side of line a-b."""
    out = []
    for i, p in enumerate(poly):
        q = poly[(i + 1) % len(poly)]
        sp, sq = side(a, b, p, sign), side(a, b, q, sign)
        if not keep_inside:
            sp, sq = -sp, -sq
        if sp >= 0.0:
            out.append(p)
        if (sp > 0.0 and sq < 0.0) or (sp < 0.0 and sq > 0.0):
            t = sp / (sp - sq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    # Drop repeated points (a vertex on the line is kept once).
    clean = []
    for p in out:
        if not clean or abs(p[0] - clean[-1][0]) + abs(p[1] - clean[-1][1]) > 1e-12:
            clean.append(p)
    if len(clean) > 1 and abs(clean[0][0] - clean[-1][0]) + abs(clean[0][1] - clean[-1][1]) <= 1e-12:
        clean.pop()
    return clean if len(clean) >= 3 and abs(area2(clean)) > 1e-14 else None


def subtract(poly, hole):
    """Convex poly minus convex hole: pieces outside, and the overlap."""
    sign = 1.0 if area2(hole) > 0 else -1.0
    pieces, rest = [], poly
    for i, a in enumerate(hole):
        b = hole[(i + 1) % len(hole)]
        outside = clip(rest, a, b, sign, False)
        if outside:
            pieces.append(outside)
        rest = clip(rest, a, b, sign, True)
        if rest is None:
            return [poly], None  # no overlap: the polygon as it was
    return pieces, rest


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: cornell_conforming.py cornell_box.obj OUT.obj")
    lines = open(sys.argv[1]).read().split("\n")
    verts, surface, faces = [], None, {}
    for line in lines:
        w = line.split()
        if not w:
            continue
        if w[0] == "o":
            surface = w[1]
        elif w[0] == "v":
            verts.append(tuple(float(x) for x in w[1:4]))
        elif w[0] == "f":
            faces.setdefault(surface, []).append([verts[int(i) - 1] for i in w[1:]])
    floor = faces["floor"]
    assert len(floor) == 1 and all(v[1] == 0.0 for v in floor[0])
    ring = [(v[0], v[2]) for v in floor[0]]
    orient = 1.0 if area2(ring) > 0 else -1.0
    polys, under = [ring], []
    for block in ("short_block", "tall_block"):
        foot = sorted({(v[0], v[2]) for f in faces[block] for v in f if v[1] == 0.0})
        # The footprint's corners in order around their centre.
        cx = sum(p[0] for p in foot) / len(foot)
        cz = sum(p[1] for p in foot) / len(foot)
        foot.sort(key=lambda p: math.atan2(p[1] - cz, p[0] - cx))
        if area2(foot) * orient < 0:
            foot.reverse()
        next_polys = []
        for p in polys:
            pieces, overlap = subtract(p, foot)
            next_polys += pieces
            if overlap:
                under.append(overlap)
        polys = next_polys
    polys += under
    total = sum(abs(area2(p)) for p in polys) / 2
    assert abs(total - abs(area2(ring)) / 2) < 1e-12, "the pieces must tile the floor"
    # Every line but the floor's; faces after it renumbered past its vertices.
    out, skip, dropped = [], False, 0
    for line in lines:
        w = line.split()
        if w and w[0] == "o":
            skip = w[1] == "floor"
        if skip:
            dropped += 1 if w and w[0] == "v" else 0
            continue
        if w and w[0] == "f":
            line = "f " + " ".join(str(int(i) - dropped) for i in w[1:])
        out.append(line)
    # The floor's pieces after everything else: indices are 1 + vertices so far.
    n = len(verts) - dropped
    body = ["", "o floor", "usemtl white"]
    for p in polys:
        for x, z in p:
            body.append("v %.17g 0 %.17g" % (x, z))
        body.append("f " + " ".join(str(n + 1 + k) for k in range(len(p))))
        n += len(p)
    header = ["# The Cornell box of tests/data/cornell_box.obj with its floor split along the",
              "# blocks' footprints (bench/cornell_conforming.py): %d convex pieces." % len(polys)]
    with open(sys.argv[2], "w") as f:
        f.write("\n".join(header + out + body) + "\n")
    shutil.copy(os.path.join(os.path.dirname(sys.argv[1]), "cornell_box.mtl"),
                os.path.join(os.path.dirname(os.path.abspath(sys.argv[2])), "cornell_box.mtl"))


if __name__ == "__main__":
    main()
