#!/usr/bin/python3
"""Per-surface radiosity of solutions against a reference, from --stats files.

    radiosity render o.obj --solver hierarchical --epsilon 3e-6 --stats ref.json
    radiosity render o.obj --solver hierarchical --epsilon 1e-3 --stats a.json
    /usr/bin/python3 bench/compare_surfaces.py ref.json a.json [b.json ...]

For each solution: leaves, links, solver seconds, the power balance, and per
kind of surface (the generated office's names: ceiling, floor, wall_, desk,
shelf, chair) the mean and rms of the relative error of the green channel.
Surfaces dark in the reference (B = 0) are skipped.
"""
import json
import math
import sys

KINDS = ("ceiling", "floor", "wall_", "desk", "shelf", "chair")


def load(path):
    with open(path) as f:
        d = json.load(f)
    surfaces = {s["name"]: s["radiosity"][1] for s in d["surfaces"]}
    return d, surfaces


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: compare_surfaces.py reference.json solution.json [...]")
    _, ref = load(sys.argv[1])
    print("%-24s %8s %9s %8s %8s  %s" % ("solution", "leaves", "links", "seconds", "power",
                                          "  ".join("%-17s" % (k + " mean/rms") for k in KINDS)))
    for path in sys.argv[2:]:
        d, got = load(path)
        h = d["solver"].get("hierarchical", {})
        p = d["power_W"]
        cells = []
        for kind in KINDS:
            e = [got[n] / b - 1.0 for n, b in ref.items() if kind in n and b > 0.0 and n in got]
            if e:
                mean = sum(e) / len(e)
                rms = math.sqrt(sum(x * x for x in e) / len(e))
                cells.append("%+6.2f%% / %5.2f%%" % (100 * mean, 100 * rms))
            else:
                cells.append("%-17s" % "-")
        print("%-24s %8s %9s %8.2f %+7.2f%%  %s" % (
            path.split("/")[-1][:24], h.get("leaves", d.get("elements", "")), h.get("links", ""),
            d["solver"].get("seconds", float("nan")),
            100 * (p["absorbed"] - p["emitted"]) / p["emitted"], "  ".join(cells)))


if __name__ == "__main__":
    main()
