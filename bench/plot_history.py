#!/usr/bin/python3
"""Plot solver convergence histories: residual (log) against seconds.

    bench/plot_history.py DIR [-o solver_convergence.png]

Reads every DIR/*.csv written by `radiosity render --history` or by
bench/bench_solvers (columns iteration,seconds,residual,unshot) and draws
one line per file.  Shooting solvers measure the residual only at the end;
where most rows have no residual the unshot power / emitted power is drawn
instead, dashed, and the legend says so.

Needs Debian's python3-matplotlib (apt-get install python3-matplotlib).
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402


def read_history(path):
    """Columns of one history CSV as lists of floats (NaN where empty)."""
    cols = {"iteration": [], "seconds": [], "residual": [], "unshot": []}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            for key in cols:
                text = (row.get(key) or "").strip()
                cols[key].append(float(text) if text else math.nan)
    return cols


def series(cols):
    """(seconds, values, measure): the residual, or the unshot power where
    fewer than half of the rows carry a residual."""
    with_residual = sum(1 for r in cols["residual"] if not math.isnan(r))
    measure = "residual" if with_residual * 2 >= len(cols["residual"]) else "unshot"
    points = [(t, v) for t, v in zip(cols["seconds"], cols[measure])
              if not math.isnan(v) and v > 0.0]
    return [p[0] for p in points], [p[1] for p in points], measure


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="folder of history CSV files")
    parser.add_argument("-o", "--output", default="solver_convergence.png", help="PNG to write")
    parser.add_argument("--title", default="Solver convergence", help="plot title")
    args = parser.parse_args()

    files = sorted(f for f in os.listdir(args.folder) if f.endswith(".csv"))
    if not files:
        sys.exit(f"plot_history: no .csv files in {args.folder}")
    fig, ax = plt.subplots(figsize=(8, 5), dpi=120)
    for name in files:
        cols = read_history(os.path.join(args.folder, name))
        seconds, values, measure = series(cols)
        if not values:
            print(f"plot_history: {name}: nothing to plot", file=sys.stderr)
            continue
        label = name[:-4]
        if label.startswith("bench_history_"):
            label = label[len("bench_history_"):]
        if measure == "unshot":
            label += " (unshot power)"
        ax.plot(seconds, values, "--" if measure == "unshot" else "-",
                marker="." if len(values) < 60 else None, label=label)
    ax.set_yscale("log")
    ax.set_xlabel("seconds")
    ax.set_ylabel("residual  (unaccounted / emitted power)")
    ax.set_title(args.title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.output)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
