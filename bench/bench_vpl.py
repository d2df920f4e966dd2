#!/usr/bin/python3
"""bench/bench_vpl.py -- instant radiosity on the built-in Cornell box: its
per-surface error against tests/data/cornell_converged.json as the light
paths grow, and its time against the other strategies at equal error.

    /usr/bin/python3 bench/bench_vpl.py [RADIOSITY_BINARY]

Every run is `radiosity render` on one thread (--threads 1, so the timings
do not depend on what else the machine runs on its other cores), seed 0,
with a 16 x 16 image; the time is the solver's (stats: solver.seconds) and
the whole run's wall clock.  Errors are relative, over the 8 surfaces x 3
channels: RMS and worst.  Prints two Markdown tables (docs/methods.md).
"""
import json
import math
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BIN = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "radiosity")
REF = json.load(open(os.path.join(ROOT, "tests", "data", "cornell_converged.json")))


def run(args):
    with tempfile.TemporaryDirectory() as work:
        stats = os.path.join(work, "s.json")
        t0 = time.monotonic()
        subprocess.run([BIN, "render", "--threads", "1", "--seed", "0", "--width", "16", "--height", "16",
                        "--quiet", "-o", os.path.join(work, "a.png"), "--stats", stats] + args, check=True)
        wall = time.monotonic() - t0
        s = json.load(open(stats))
    got = {x["name"]: x["radiosity"] for x in s["surfaces"]}
    errors = [got[r["name"]][c] / r["radiosity"][c] - 1.0 for r in REF["surfaces"] for c in range(3)]
    rms = math.sqrt(sum(e * e for e in errors) / len(errors))
    worst = max(abs(e) for e in errors)
    return s, rms, worst, wall


def main():
    print("Convergence against light paths (RMS / worst relative error per surface and channel):\n")
    print("| paths | VPLs | r_c (m) | clamped RMS | clamped worst | clamp loss | compensated RMS | "
          "compensated worst | solve s |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for paths in (16, 64, 256, 1024, 4096):
        a, rms_a, worst_a, _ = run(["--solver", "instant-radiosity-clamped", "--ff-samples", str(paths)])
        b, rms_b, worst_b, _ = run(["--solver", "instant-radiosity", "--ff-samples", str(paths)])
        ir = b["solver"]["instant_radiosity"]
        print("| %d | %d | %.4f | %.2f%% | %.2f%% | %.2f%% | %.2f%% | %.2f%% | %.2f |" %
              (paths, ir["lights"], ir["clamp_radius_m"], 100 * rms_a, 100 * worst_a,
               100 * a["solver"]["instant_radiosity"]["clamp_loss"], 100 * rms_b, 100 * worst_b,
               b["solver"]["seconds"]))
    print("\nTime against the other strategies (one thread):\n")
    print("| strategy (options) | RMS | worst | solve s | wall s |")
    print("|---|---:|---:|---:|---:|")
    runs = [
        ("instant-radiosity (`--ff-samples 1024`)", ["--solver", "instant-radiosity", "--ff-samples", "1024"]),
        ("instant-radiosity (`--ff-samples 4096`)", ["--solver", "instant-radiosity", "--ff-samples", "4096"]),
        ("shooting (`--ff-samples 256`)", ["--solver", "shooting", "--ff-samples", "256"]),
        ("shooting (`--ff-samples 64`)", ["--solver", "shooting", "--ff-samples", "64"]),
        ("gauss-seidel, analytic (`--elements 300`)", ["--solver", "gauss-seidel", "--elements", "300"]),
        ("gauss-seidel, analytic (`--elements 2000`)", ["--solver", "gauss-seidel"]),
        ("hierarchical (default)", []),
    ]
    for name, args in runs:
        s, rms, worst, wall = run(args)
        print("| %s | %.2f%% | %.2f%% | %.2f | %.2f |" % (name, 100 * rms, 100 * worst, s["solver"]["seconds"], wall))
    print("\nPer pixel (`render --vpl N --samples 1`, 64 x 64, one thread) against the mean of four seeds' "
          "renders at 16384 paths; RMS of the relative error over lit pixels, and against the smooth "
          "gauss-seidel render of 10,000 elements (the element solution's own mesh error included):\n")
    print("| paths | RMS vs 16384 paths | RMS vs gauss-seidel 10k | render s |")
    print("|---:|---:|---:|---:|")
    ref = None
    for seed in range(4):
        img = render_pfm(["--solver", "instant-radiosity", "--ff-samples", "16", "--vpl", "16384", "--seed",
                          str(seed)])[0]
        ref = img if ref is None else [a + b for a, b in zip(ref, img)]
    ref = [v / 4.0 for v in ref]
    gs = render_pfm(["--solver", "gauss-seidel", "--elements", "10000"])[0]
    for paths in (16, 64, 256, 1024, 4096):
        img, seconds, s = render_pfm(["--solver", "instant-radiosity", "--ff-samples", "16", "--vpl", str(paths)])
        print("| %d | %.1f%% | %.1f%% | %.2f |" % (paths, 100 * pixel_rms(img, ref), 100 * pixel_rms(img, gs),
                                                   seconds))


def render_pfm(args):
    import struct
    with tempfile.TemporaryDirectory() as work:
        out = os.path.join(work, "a.pfm")
        stats = os.path.join(work, "s.json")
        subprocess.run([BIN, "render", "--threads", "1", "--width", "64", "--height", "64", "--samples", "1",
                        "--quiet", "-o", out, "--stats", stats] + args, check=True)
        s = json.load(open(stats))
        with open(out, "rb") as f:
            f.readline()
            w, h = (int(v) for v in f.readline().split())
            scale = float(f.readline())
            data = f.read()
        pixels = struct.unpack(("<" if scale < 0 else ">") + "%df" % (w * h * 3), data)
    return list(pixels), s["seconds"]["render"] if "seconds" in s and "render" in s["seconds"] else float("nan"), s


def pixel_rms(img, ref):
    errors = [(a / b - 1.0) ** 2 for a, b in zip(img, ref) if b > 1e-3 * max(ref)]
    return math.sqrt(sum(errors) / len(errors))


if __name__ == "__main__":
    main()
