#!/usr/bin/env python3
"""RMS z = (F - exact) / std_error of montecarlo's view factors against the analytic
ones, over seeds (docs/methods.md, "Calibrated errors").  LEVEL=surface|element.
usage: bench/ff_sigma_z.py RADIOSITY cube|box123|par|perp ELEMENTS SEEDS [options]"""
import json, math, os, subprocess, sys

binary, scene, elements, seeds = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
level = os.environ.get("LEVEL", "element")
extra = sys.argv[5:]
work = "/tmp/ff_sigma_z_%s_%s_%d" % (scene, elements, os.getpid())
os.makedirs(work, exist_ok=True)

def quad(name, p):
    return "o %s\nusemtl w\n" % name + "".join("v %g %g %g\n" % v for v in p) + "f -4 -3 -2 -1\n"

def box(a, b, c):  # inward normals (the quads below reversed)
    q = lambda name, p: quad(name, p[::-1])
    return (q("x0", [(0,0,0),(0,0,c),(0,b,c),(0,b,0)]) + q("x1", [(a,0,0),(a,b,0),(a,b,c),(a,0,c)]) +
            q("y0", [(0,0,0),(a,0,0),(a,0,c),(0,0,c)]) + q("y1", [(0,b,0),(0,b,c),(a,b,c),(a,b,0)]) +
            q("z0", [(0,0,0),(0,b,0),(a,b,0),(a,0,0)]) + q("z1", [(0,0,c),(a,0,c),(a,b,c),(0,b,c)]))

if scene == "cube": text = box(1, 1, 1)
elif scene == "box123": text = box(1, 2, 3)
elif scene == "par":  # two unit squares a metre apart, facing
    text = quad("A1", [(0,0,0),(1,0,0),(1,1,0),(0,1,0)]) + quad("A2", [(0,0,1),(0,1,1),(1,1,1),(1,0,1)])
elif scene == "perp":  # two unit squares sharing an edge
    text = quad("A1", [(0,0,0),(1,0,0),(1,1,0),(0,1,0)]) + quad("A2", [(0,0,0),(0,1,0),(0,1,1),(0,0,1)])
obj = os.path.join(work, "s.obj")
open(obj, "w").write("mtllib s.mtl\n" + text)
open(os.path.join(work, "s.mtl"), "w").write("newmtl w\nKd 0.5 0.5 0.5\n")

def vf(method, seed, opts):
    out = os.path.join(work, "%s_%d.json" % (method, seed))
    subprocess.run([binary, "viewfactors", obj, "-o", out, "--level", level, "--elements", elements,
                    "--form-factors", method, "--seed", str(seed), "--threads", "1"] + opts, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return json.load(open(out))

exact = vf("analytic", 0, [])
E = exact["F"]
n = len(E)
zz, count, zmax, rowz = 0.0, 0, 0.0, []
by_kind = {}
for seed in range(seeds):
    m = vf("montecarlo", seed, extra)
    F, S = m["F"], m["F_std_error"]
    for i in range(n):
        for j in range(n):
            if E[i][j] <= 0 and F[i][j] <= 0:
                continue
            if S[i][j] <= 0:
                continue
            z = (F[i][j] - E[i][j]) / S[i][j]
            zz += z * z; count += 1; zmax = max(zmax, abs(z))
            L = m.get("elements_list") or [{"surface": s["name"], "name": s["name"]} for s in m["surfaces"]]
            key = "same" if L[i]["surface"] == L[j]["surface"] else ("opp" if L[i]["surface"][0] == L[j]["surface"][0] else "adj")
            b = by_kind.setdefault(key, [0.0, 0, []])
            b[0] += z * z; b[1] += 1
            if abs(z) > 20: b[2].append((round(z, 1), L[i]["name"], L[j]["name"], F[i][j], E[i][j], S[i][j]))
print("%s %s elements, n %d, %d seeds %s: RMS z %.3f over %d factors, max |z| %.1f" %
      (scene, elements, n, seeds, " ".join(extra), math.sqrt(zz / max(count, 1)), count, zmax))
for k, b in sorted(by_kind.items()):
    print("  %s: RMS z %.3f over %d; |z| > 20: %d %s" % (k, math.sqrt(b[0] / b[1]), b[1], len(b[2]), b[2][:4]))
