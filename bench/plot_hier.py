#!/usr/bin/python3
"""Log-log plot of links and seconds against leaves from bench_hier --csv.

    ./build/bench/bench_hier --csv hier.csv && /usr/bin/python3 bench/plot_hier.py hier.csv out.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: plot_hier.py hier.csv out.png")
    rows = list(csv.DictReader(open(sys.argv[1])))
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    series = (("Cornell box", "o", lambda n: n == "cornell"),
              ("offices, epsilon 1e-3", "s", lambda n: n.startswith("office")),
              ("offices, epsilon 1e-3 / rooms", "D", lambda n: n.startswith("perroom")),
              ("Cornell, --oracle classic", "^", lambda n: n == "cornell_classic"))
    for label, marker, pick in series:
        sel = [r for r in rows if pick(r["scene"])]
        if not sel:
            continue
        leaves = [float(r["leaves"]) for r in sel]
        axes[0].loglog(leaves, [float(r["links"]) for r in sel], marker=marker, label=label)
        axes[1].loglog(leaves, [float(r["seconds"]) for r in sel], marker=marker, label=label)
    # The peer hierarchical Galerkin solver of issue #5, measured elsewhere.
    axes[0].loglog([5398], [42475], "kx", label="peer")
    axes[1].loglog([5398], [0.55], "kx", label="peer")
    lo = min(float(r["leaves"]) for r in rows)
    hi = max(float(r["leaves"]) for r in rows)
    axes[0].loglog([lo, hi], [10 * lo, 10 * hi], "k:", label="10 links per leaf")
    axes[0].set_xlabel("leaves (elements)")
    axes[0].set_ylabel("links")
    axes[1].set_xlabel("leaves (elements)")
    axes[1].set_ylabel("seconds (2 cores)")
    for a in axes:
        a.grid(True, which="both", alpha=0.3)
        a.legend()
    fig.suptitle("Hierarchical radiosity: links and time against elements")
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=100)


if __name__ == "__main__":
    main()
