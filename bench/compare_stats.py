#!/usr/bin/env python3
"""compare_stats.py BEFORE AFTER: compare the stats JSON and view-factor files of two
stats_runs.sh folders, key by key, ignoring what a run cannot repeat (seconds, memory,
the version).  Prints the differences and "identical" or "N files differ"."""
import json, sys, os, glob
IGN = {"seconds", "peak_resident", "seconds_refine", "seconds_solve", "seconds_mesh", "version", "memory_bytes", "total"}
def walk(a, b, path, diffs):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k in IGN or k.startswith("seconds"):
                continue
            if k not in a or k not in b:
                diffs.append(f"{path}/{k}: only in {'after' if k in b else 'before'}")
                continue
            walk(a[k], b[k], f"{path}/{k}", diffs)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            diffs.append(f"{path}: length {len(a)} -> {len(b)}"); return
        for i, (x, y) in enumerate(zip(a, b)):
            walk(x, y, f"{path}[{i}]", diffs)
    elif a != b:
        diffs.append(f"{path}: {a!r} -> {b!r}")
before, after = sys.argv[1], sys.argv[2]
bad = 0
for f in sorted(glob.glob(os.path.join(before, "*.json"))):
    g = os.path.join(after, os.path.basename(f))
    if not os.path.exists(g):
        print(f"{os.path.basename(f)}: missing after"); bad += 1; continue
    try:
        d = []; walk(json.load(open(f)), json.load(open(g)), "", d)
    except Exception as e:
        print(f"{os.path.basename(f)}: {e}"); bad += 1; continue
    if d:
        bad += 1
        print(f"{os.path.basename(f)}: {len(d)} differences"); [print("   ", x) for x in d[:8]]
for f in sorted(glob.glob(os.path.join(before, "*.mtx")) + glob.glob(os.path.join(before, "*.csv"))):
    g = os.path.join(after, os.path.basename(f))
    if not os.path.exists(g) or open(f).read() != open(g).read():
        print(f"{os.path.basename(f)}: differs"); bad += 1
print("identical" if not bad else f"{bad} files differ")
