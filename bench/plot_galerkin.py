#!/usr/bin/python3
"""Log-log SVG of error against unknowns from bench_galerkin, with the
orders fitted over the finest three meshes (plain SVG: no matplotlib).

    ./build/bench/bench_galerkin floor > floor.txt
    ./build/bench/bench_galerkin triangle > triangle.txt
    ./build/bench/bench_galerkin cornell > cornell.txt
    /usr/bin/python3 bench/plot_galerkin.py floor.txt triangle.txt cornell.txt docs/galerkin_convergence.svg

The order p (error ~ h^p) is the least-squares slope of log(error)
against log(h) over the finest three meshes, h the element size the
bench prints; without it, -2 x the slope against log(unknowns) (unknowns
~ h^-2 only asymptotically: (n+1)^2 vertices for n^2 elements inflate it).
"""
import math
import sys

COLOURS = {"galerkin-constant": "#1f77b4", "galerkin-linear": "#d62728", "collocation": "#2ca02c"}
MARKERS = {"galerkin-constant": "circle", "galerkin-linear": "square", "collocation": "diamond"}


def read(path):
    title, series = None, {}
    for line in open(path):
        if line.startswith("#"):
            title = line[1:].split(":")[0].strip()
            continue
        parts = line.split()
        if len(parts) not in (4, 5):
            continue
        h = float(parts[4]) if len(parts) == 5 else None
        series.setdefault(parts[0], []).append((float(parts[1]), float(parts[2]), float(parts[3]), h))
    return title, series


def order(points, last=3):
    """Least-squares slope of log error against log h (or log unknowns), as an order in h."""
    pts = points[-last:]
    by_h = all(p[3] for p in pts)
    xs = [math.log(p[3]) if by_h else math.log(p[0]) for p in pts]
    ys = [math.log(p[1]) for p in pts]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    sxy = sum((x - mx) * (y - my) for x, y in zip(xs, ys))
    return sxy / sxx if by_h else -2.0 * sxy / sxx


def panel(out, x0, y0, w, h, title, series):
    xs = [p[0] for s in series.values() for p in s]
    ys = [p[1] for s in series.values() for p in s]
    lx0, lx1 = math.floor(math.log10(min(xs))), math.ceil(math.log10(max(xs)))
    ly0, ly1 = math.floor(math.log10(min(ys))), math.ceil(math.log10(max(ys)))

    def px(v):
        return x0 + (math.log10(v) - lx0) / (lx1 - lx0) * w

    def py(v):
        return y0 + h - (math.log10(v) - ly0) / (ly1 - ly0) * h

    out.append(f'<rect x="{x0}" y="{y0}" width="{w}" height="{h}" fill="none" stroke="black"/>')
    for d in range(lx0, lx1 + 1):
        X = px(10 ** d)
        out.append(f'<line x1="{X:.1f}" y1="{y0}" x2="{X:.1f}" y2="{y0 + h}" stroke="#ddd"/>')
        out.append(f'<text x="{X:.1f}" y="{y0 + h + 16}" text-anchor="middle" font-size="12">1e{d}</text>')
    for d in range(ly0, ly1 + 1):
        Y = py(10 ** d)
        out.append(f'<line x1="{x0}" y1="{Y:.1f}" x2="{x0 + w}" y2="{Y:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{x0 - 6}" y="{Y + 4:.1f}" text-anchor="end" font-size="12">1e{d}</text>')
    out.append(f'<text x="{x0 + w / 2}" y="{y0 - 8}" text-anchor="middle" font-size="14">{title}</text>')
    out.append(f'<text x="{x0 + w / 2}" y="{y0 + h + 34}" text-anchor="middle" font-size="12">unknowns</text>')
    out.append(f'<text x="{x0 - 44}" y="{y0 + h / 2}" text-anchor="middle" font-size="12" '
               f'transform="rotate(-90 {x0 - 44} {y0 + h / 2})">relative error</text>')
    ly = y0 + 14
    for name, pts in series.items():
        c = COLOURS.get(name, "black")
        path = " ".join(f"{px(p[0]):.1f},{py(p[1]):.1f}" for p in pts)
        out.append(f'<polyline points="{path}" fill="none" stroke="{c}" stroke-width="2"/>')
        for p in pts:
            X, Y = px(p[0]), py(p[1])
            if MARKERS[name] == "square":
                out.append(f'<rect x="{X - 4:.1f}" y="{Y - 4:.1f}" width="8" height="8" fill="{c}"/>')
            elif MARKERS[name] == "diamond":
                out.append(f'<polygon points="{X:.1f},{Y - 5:.1f} {X + 5:.1f},{Y:.1f} {X:.1f},{Y + 5:.1f} '
                           f'{X - 5:.1f},{Y:.1f}" fill="{c}"/>')
            else:
                out.append(f'<circle cx="{X:.1f}" cy="{Y:.1f}" r="4" fill="{c}"/>')
        out.append(f'<text x="{x0 + w - 8}" y="{ly}" text-anchor="end" font-size="12" fill="{c}">'
                   f'{name}: order {order(pts):.2f}</text>')
        ly += 16


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: plot_galerkin.py BENCH.txt... OUT.svg")
    inputs, target = sys.argv[1:-1], sys.argv[-1]
    W, H, pw, ph = 420 * len(inputs), 380, 320, 270
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif">',
           f'<rect width="{W}" height="{H}" fill="white"/>']
    for k, path in enumerate(inputs):
        title, series = read(path)
        panel(out, 70 + 420 * k, 40, pw, ph, title, series)
        for name, pts in series.items():
            print(f"{title} {name}: order {order(pts):.2f} over the finest three")
    out.append("</svg>")
    open(target, "w").write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
