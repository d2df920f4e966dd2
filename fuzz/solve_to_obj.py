#!/usr/bin/env python3
"""Write a fuzz_solve input as an OBJ + MTL, to reproduce it with the CLI.

    fuzz/solve_to_obj.py INPUT OUT.obj    # prints the CLI options it implies

The decoding mirrors fuzz/fuzz_solve.c (its header comment is the format)."""
import os
import struct
import sys

METHODS = [("gauss-seidel", "analytic"), ("jacobi", "hemicube --hemicube-resolution 32"),
           ("shooting", None), ("hierarchical", None), ("direct", "contour"),
           ("conjugate-gradient", "hemisphere"), ("southwell", "hybrid"),
           ("gauss-seidel", "montecarlo")]
MATERIALS = [("lamp", (0.3, 0.3, 0.3), 10.0), ("white", (0.8, 0.8, 0.8), 0.0),
             ("red", (0.7, 0.1, 0.1), 0.0), ("black", (0.0, 0.0, 0.0), 0.0)]


def main(src, out):
    data = open(src, "rb").read()
    raw, scale, p = data[0] & 0x20, 2.0 ** (data[1] - 128), 2
    polygons = []

    def coordinate():
        nonlocal p
        if raw:
            if len(data) - p < 4:
                return 0.0
            p += 4
            return struct.unpack("<f", data[p - 4:p])[0]
        if p >= len(data):
            return 0.0
        p += 1
        return struct.unpack("b", data[p - 1:p])[0] / 16.0 * scale

    while p < len(data) and len(polygons) < 12:
        head = data[p]
        p += 1
        corners = [(coordinate(), coordinate(), coordinate()) for _ in range(3 + (head & 3))]
        polygons.append(((head >> 2) & 3, corners))
    mtl = os.path.splitext(out)[0] + ".mtl"
    with open(mtl, "w") as f:
        for name, rho, e in MATERIALS:
            ke = e / 3.141592653589793  # Ke is emitted radiance: E / pi
            f.write(f"newmtl {name}\nKd {rho[0]} {rho[1]} {rho[2]}\nKe {ke!r} {ke!r} {ke!r}\n")
    with open(out, "w") as f:
        f.write(f"mtllib {os.path.basename(mtl)}\n")
        n = 0
        for m, corners in polygons:
            f.write(f"o {MATERIALS[m][0]}\nusemtl {MATERIALS[m][0]}\n")
            for c in corners:
                f.write("v %r %r %r\n" % c)
            f.write("f " + " ".join(str(n + k + 1) for k in range(len(corners))) + "\n")
            n += len(corners)
    solver, ff = METHODS[data[0] & 7]
    opts = f"--solver {solver} --elements {8 << ((data[0] >> 3) & 3)} --max-iterations 200 --seed 1"
    if solver == "hierarchical":
        opts += " --epsilon 1e-3"
    if ff:
        opts += f" --form-factors {ff}"
    print(opts)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
