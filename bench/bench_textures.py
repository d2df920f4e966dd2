#!/usr/bin/python3
"""bench/bench_textures.py -- what a reflectance texture (map_Kd) costs and
whether its energy is right.

    /usr/bin/python3 bench/bench_textures.py [RADIOSITY_BINARY]

A 1 m x 1 m floor under a square lamp, its material Kd 0.9 with a
1024 x 1024 PNG checker of 32 x 32 cells (sRGB 220 and 30), against the
same floor untextured with Kd = 0.9 x the texels' linear mean.  Each run is
`radiosity render --threads 1 --solver gauss-seidel --elements N` (512 x 512
image); printed: wall seconds, the render phase's seconds, and the floor's
mean radiosity (its reflected power / area: equal for the two when the
per-element means are right).
"""
import json
import os
import struct
import subprocess
import sys
import tempfile
import time
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
BIN = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(HERE), "build", "radiosity")


def linear(s):
    c = s / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def write_png(path, size, cells, a, b):
    rows = []
    for y in range(size):
        row = bytearray([0])
        for x in range(size):
            v = a if ((x * cells // size) + (y * cells // size)) % 2 == 0 else b
            row += bytes((v, v, v))
        rows.append(bytes(row))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xffffffff)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(b"".join(rows))) + chunk(b"IEND", b""))


def write_scene(folder, floor):
    with open(os.path.join(folder, "s.mtl"), "w") as f:
        f.write("newmtl floor\n%s\nnewmtl lamp\nKd 0 0 0\nKe 1 1 1\n" % floor)
    with open(os.path.join(folder, "s.obj"), "w") as f:
        f.write("mtllib s.mtl\nv 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                "v 0.3 1 0.3\nv 0.7 1 0.3\nv 0.7 1 0.7\nv 0.3 1 0.7\n"
                "o floor\nusemtl floor\nf 1/1 4/4 3/3 2/2\no lamp\nusemtl lamp\nf 5 6 7 8\n"
                "# radiosity camera: 0.5 0.9 0.5 0.5 0 0.5 0 0 -1 90\n")


def run(folder, elements):
    stats = os.path.join(folder, "s.json")
    t0 = time.monotonic()
    subprocess.run([BIN, "render", os.path.join(folder, "s.obj"), "--threads", "1", "--solver", "gauss-seidel",
                    "--elements", str(elements), "--quiet", "-o", os.path.join(folder, "a.png"), "--stats", stats],
                   check=True)
    wall = time.monotonic() - t0
    s = json.load(open(stats))
    floor = [x for x in s["surfaces"] if x["name"] == "floor"][0]["radiosity"][0]
    return wall, s["seconds"]["render"], floor


def main():
    with tempfile.TemporaryDirectory() as folder:
        write_png(os.path.join(folder, "checker.png"), 1024, 32, 220, 30)
        mean = 0.9 * 0.5 * (linear(220) + linear(30))
        print("| elements | floor | wall s | render s | floor mean B (W/m^2) |")
        print("|---:|---|---:|---:|---:|")
        for elements in (1000, 10000):
            for name, floor in (("1024^2 texture", "Kd 0.9 0.9 0.9\nmap_Kd checker.png"),
                                ("flat, the texture's mean", "Kd %.17g %.17g %.17g" % (mean, mean, mean))):
                write_scene(folder, floor)
                wall, render, b = run(folder, elements)
                print("| %d | %s | %.2f | %.2f | %.6f |" % (elements, name, wall, render, b))


if __name__ == "__main__":
    main()
