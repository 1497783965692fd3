#!/usr/bin/python3
"""Rigs rectified back with cubic / Lanczos interpolation (this folder's R/) against the rectified
family of /tmp/r37/R, the way analyze.py's 'paired against the family's geometric mean' does."""
import math, sys
from collections import defaultdict
import numpy as np
sys.path.insert(0, "/work/main/scripts/experiments/rig_vs_rectified")
import analyze as A

OLD, NEW = "/tmp/r37", "/tmp/r37c"
import os
SEEDS = [int(x) for x in os.environ.get("SEEDS", "1,3,4,5,6,7,8,9,10").split(",")]
FAMILY = A.FAMILY
OBJ = A.OBJ_METRICS
NEWIN = [f"{l}_{i}" for l in ["radtan", "equidistant"] for i in ["lanczos", "cubic"]]

data = {}
for s in SEEDS:
    row = {i: A.load(OLD, s, i) for i in A.MAIN}
    for i in NEWIN:
        row[i] = A.load(NEW, s, i)
    data[s] = row
avail = {i: [s for s in SEEDS if data[s][i] is not None] for i in A.MAIN + NEWIN}
print("runs available:", {i: len(v) for i, v in avail.items()}, "\n")
lost = [(s, i) for s in SEEDS for i in A.MAIN + NEWIN if data[s][i] and data[s][i]["camera"]["ate_m"] > A.LOST_M]
print("camera lost (> 1 m):", lost or "none", "\n")
fo = A.found_objects

def fam_ref(s, g, k, members):
    vals = []
    for i in members:
        d = {o["gt_object"]: o for o in fo(data[s][i])}
        if g not in d:
            return None
        vals.append(d[g][k])
    return math.exp(np.mean(np.log(vals)))

def ratios_vs(inp, members):
    out = []
    for s in avail[inp]:
        b = {o["gt_object"]: o for o in fo(data[s][inp])}
        for g in b:
            r = {}
            for k, _ in OBJ:
                ref = fam_ref(s, g, k, members)
                if ref is None:
                    break
                r[k] = b[g][k] / ref
            else:
                out.append((s, r))
    return out

def boot_ci(rows, k, nb=4000, seed=7):
    rng = np.random.default_rng(seed)
    by = defaultdict(list)
    for s, r in rows:
        by[s].append(math.log(r[k]))
    ss = sorted(by)
    est = math.exp(np.mean([v for s in ss for v in by[s]]))
    bs = []
    for _ in range(nb):
        pick = rng.choice(ss, len(ss))
        bs.append(np.mean([x for s in pick for x in by[s]]))
    lo, hi = np.percentile(bs, [2.5, 97.5])
    return est, math.exp(lo), math.exp(hi)

print("### Objects paired against the family's geometric mean (rect+noise1+noise2; objects found by all three); "
      "bias [95 % seed-bootstrap CI], scatter = median |ratio-1|\n")
print("| input | seeds | objects | object ATE | ME_r | ME_t |")
print("|---|---|---|---|---|---|")
combos = [("rect", ["noise1", "noise2"]), ("noise1", ["rect", "noise2"]), ("noise2", ["rect", "noise1"]),
          ("radtan", FAMILY), ("radtan_lanczos", FAMILY), ("radtan_cubic", FAMILY),
          ("equidistant", FAMILY), ("equidistant_lanczos", FAMILY), ("equidistant_cubic", FAMILY)]
for inp, members in combos:
    if not avail[inp]:
        continue
    rows = ratios_vs(inp, members)
    cells = []
    for k, _ in OBJ:
        e, lo, hi = boot_ci(rows, k)
        sc = np.median([abs(r[k] - 1) for _, r in rows]) * 100
        cells.append(f"{e:.2f} [{lo:.2f}, {hi:.2f}], {sc:.0f}%")
    ref = "geo. mean of " + "+".join(members)
    lab = inp + ("" if inp in A.MAIN[:3] else "") + (" (bilinear, /tmp/r37)" if inp in ("radtan", "equidistant") else "")
    print(f"| {lab} vs {ref} | {len(avail[inp])} | {len(rows)} | " + " | ".join(cells) + " |")
print()

print("### Camera ATE against the family's geometric mean per seed; bias [95 % seed-bootstrap CI]\n")
print("| input | seeds | camera ATE bias | pooled median camera ATE (m) | clustering accuracy median |")
print("|---|---|---|---|---|")
rng = np.random.default_rng(11)
for inp, members in combos:
    ss = avail[inp]
    if not ss:
        continue
    lr = np.array([math.log(data[s][inp]["camera"]["ate_m"]) - np.mean([math.log(data[s][i]["camera"]["ate_m"]) for i in members]) for s in ss])
    bs = [np.mean(rng.choice(lr, len(lr))) for _ in range(4000)]
    lo, hi = np.percentile(bs, [2.5, 97.5])
    print(f"| {inp} | {len(ss)} | {math.exp(lr.mean()):.2f} [{math.exp(lo):.2f}, {math.exp(hi):.2f}] | "
          f"{A.med([data[s][inp]['camera']['ate_m'] for s in ss]):.4f} | {A.med([data[s][inp]['clustering']['accuracy'] for s in ss]):.3f} |")
print()

print("### Direct pairing: sharper interpolation / bilinear, same lens, per object found by both; bias [95 % CI], scatter\n")
print("| input vs bilinear | objects | object ATE | ME_r | ME_t | camera ATE (per seed) |")
print("|---|---|---|---|---|---|")
for inp in NEWIN:
    base = inp.split("_")[0]
    ss = avail[inp]
    if not ss:
        continue
    rows = []
    for s in ss:
        a = {o["gt_object"]: o for o in fo(data[s][base])}
        b = {o["gt_object"]: o for o in fo(data[s][inp])}
        for g in sorted(set(a) & set(b)):
            rows.append((s, {k: b[g][k] / a[g][k] for k, _ in OBJ}))
    cells = []
    for k, _ in OBJ:
        e, lo, hi = boot_ci(rows, k)
        sc = np.median([abs(r[k] - 1) for _, r in rows]) * 100
        cells.append(f"{e:.2f} [{lo:.2f}, {hi:.2f}], {sc:.0f}%")
    cr = [data[s][inp]["camera"]["ate_m"] / data[s][base]["camera"]["ate_m"] for s in ss]
    print(f"| {inp} | {len(rows)} | " + " | ".join(cells) + f" | {math.exp(np.mean(np.log(cr))):.2f} |")
print()

print("### Pooled medians over the seeds (found objects)\n")
print("| input | camera ATE (m) | objects found | object ATE (m) | ME_r (deg) | ME_t (m) |")
print("|---|---|---|---|---|---|")
for inp in A.MAIN + NEWIN:
    ss = avail[inp]
    if not ss:
        continue
    f = [o for s in ss for o in fo(data[s][inp])]
    print(f"| {inp} | {A.med([data[s][inp]['camera']['ate_m'] for s in ss]):.4f} | {len(f)} | "
          f"{A.med([o['ate_m'] for o in f]):.3f} | {A.med([o['me_r_deg'] for o in f]):.3f} | {A.med([o['me_t_m'] for o in f]):.4f} |")
print()

print("### Per seed: camera ATE (mm) and objects found\n")
cols = A.MAIN + NEWIN
print("| seed | " + " | ".join(cols) + " |")
print("|---|" + "---|" * len(cols))
for s in SEEDS:
    print(f"| {s} | " + " | ".join(
        (f"{data[s][i]['camera']['ate_m']*1000:.1f}, {len(fo(data[s][i]))}" if data[s][i] else "—") for i in cols) + " |")
