#!/usr/bin/python3
"""Per-surface radiosity extrapolated to zero element size (Richardson).

    /usr/bin/python3 bench/richardson.py OUT.json STATS.json STATS.json ...

Each STATS.json is the --stats file of one solution of the same scene on a
finer and finer mesh (bench/cornell_reference.sh makes them).  Its element
size is taken as h = sqrt(total area / elements), so that meshes whose
grids round differently per patch still line up.  For every surface and
channel the area means B(h) are fitted by B(h) = B0 + c h^p (Richardson
extrapolation with the order p estimated, not assumed): for each p on a grid
from 0.3 to 4 the least-squares B0 and c, keeping the p of least residual;
with three meshes the fit is exact.  The same fit on the finest three meshes
alone gives a second B0: their difference, and the distance from the finest
mesh's value, are written as the uncertainty and the correction.

OUT.json: {"surfaces": [{"name", "radiosity": [R, G, B], "order": [p...],
"finest": [R, G, B], "uncertainty": [...]}], "meshes": [{"elements", "h_m"}],
"how": "..."}.
"""
import json
import math
import sys


def fit(hs, bs):
    """Least-squares B0 + c h^p over a grid of p; returns (B0, c, p, rms)."""
    best = None
    for k in range(30, 401):
        p = k / 100.0
        xs = [h ** p for h in hs]
        n = len(xs)
        mx, mb = sum(xs) / n, sum(bs) / n
        sxx = sum((x - mx) ** 2 for x in xs)
        c = sum((x - mx) * (b - mb) for x, b in zip(xs, bs)) / sxx
        b0 = mb - c * mx
        rms = math.sqrt(sum((b0 + c * x - b) ** 2 for x, b in zip(xs, bs)) / n)
        if best is None or rms < best[3]:
            best = (b0, c, p, rms)
    return best


def main():
    if len(sys.argv) < 5:
        sys.exit("usage: richardson.py OUT.json STATS.json STATS.json STATS.json [...]")
    runs = []
    for path in sys.argv[2:]:
        with open(path) as f:
            d = json.load(f)
        area = sum(s["area"] for s in d["surfaces"])
        runs.append((math.sqrt(area / d["elements"]), d))
    runs.sort(key=lambda r: -r[0])  # coarse to fine
    hs = [h for h, _ in runs]
    out = []
    for i, s in enumerate(runs[-1][1]["surfaces"]):
        row = {"name": s["name"], "radiosity": [], "order": [], "finest": [], "uncertainty": []}
        for c in range(3):
            bs = [d["surfaces"][i]["radiosity"][c] for _, d in runs]
            b0, _, p, _ = fit(hs, bs)
            b0_fine, _, _, _ = fit(hs[-3:], bs[-3:])
            row["radiosity"].append(b0)
            row["order"].append(p)
            row["finest"].append(bs[-1])
            row["uncertainty"].append(abs(b0 - b0_fine))
        out.append(row)
    result = {
        "how": "area-mean radiosity per surface (W/m^2, RGB) of the built-in Cornell box, "
               "extrapolated to zero element size by bench/richardson.py from the --stats files "
               "of bench/cornell_reference.sh (uniform meshes of the box with its floor split along "
               "the blocks' footprints, bench/cornell_conforming.py; gauss-seidel, analytic form "
               "factors, seed 0); order: the fitted p (0.3 or 4 at the ends of the searched range: "
               "the values no longer move beyond their noise); uncertainty: the extrapolation from all meshes against the "
               "one from the finest three",
        "meshes": [{"elements": d["elements"], "h_m": h} for h, d in runs],
        "surfaces": out,
    }
    with open(sys.argv[1], "w") as f:
        json.dump(result, f, indent=1)
        f.write("\n")
    print("%-12s %10s %10s %10s  %6s  %s" % ("surface", "B0 green", "finest", "corr.", "p", "uncert. (R,G,B)"))
    for r in out:
        print("%-12s %10.6f %10.6f %+9.3f%%  %6.2f  %s" % (
            r["name"], r["radiosity"][1], r["finest"][1], 100 * (r["finest"][1] / r["radiosity"][1] - 1),
            r["order"][1], " ".join("%.3f%%" % (100 * u / b) for u, b in zip(r["uncertainty"], r["radiosity"]))))


if __name__ == "__main__":
    main()
