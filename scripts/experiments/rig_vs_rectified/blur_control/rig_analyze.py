#!/usr/bin/python3
"""Rig control: object metrics of rectified-back distorted rigs (current binary) vs the direct-rendering family.
Family runs: /tmp/blur/R (same binary); rig runs: /tmp/blur2/R. Helpers copied from /tmp/blur/analyze.py."""
import json, math, os, sys
import numpy as np

ALLSEEDS = [1, 3, 4, 5, 6, 7, 8, 9, 10]
PATHS = {"rect": "/tmp/blur/R/s{n}", "noise1": "/tmp/blur/R/s{n}_noise1", "noise2": "/tmp/blur/R/s{n}_noise2",
         "radtan": "/tmp/blur2/R/s{n}_radtan", "equidistant": "/tmp/blur2/R/s{n}_equidistant"}
FAMILY = ["rect", "noise1", "noise2"]
RIGS = ["radtan", "equidistant"]
INPUTS = RIGS + FAMILY
METRICS = [("ate_m", "obj ATE m"), ("me_r_deg", "ME_r deg"), ("me_t_m", "ME_t m")]
NBOOT = 2000
rng = np.random.default_rng(12345)

# seeds with both rig runs present
SEEDS = [n for n in ALLSEEDS if all(os.path.exists(PATHS[r].format(n=n) + "/metrics.json") for r in RIGS)]

def load(inp, n):
    d = json.load(open(PATHS[inp].format(n=n) + "/metrics.json"))
    objs = {}
    for o in d["objects"]["per_object"]:
        if o["found"]:
            objs[o["gt_object"]] = o
    return d["camera"]["ate_m"], objs, len(d["objects"]["per_object"])

data = {inp: {n: load(inp, n) for n in SEEDS} for inp in INPUTS}

def med(v):
    return float(np.median(v)) if len(v) else float("nan")

out = []
P = out.append
P(f"Seeds analysed: {SEEDS}\n")

P("## Per-seed results\n")
P("| seed | input | camera ATE m | objects found / gt | median obj ATE m | median ME_r deg | median ME_t m |")
P("|---|---|---|---|---|---|---|")
for n in SEEDS:
    for inp in INPUTS:
        cam, objs, ngt = data[inp][n]
        vals = {k: [o[k] for o in objs.values() if o[k] is not None] for k, _ in METRICS}
        P(f"| {n} | {inp} | {cam:.4f} | {len(objs)} / {ngt} | {med(vals['ate_m']):.4f} | "
          f"{med(vals['me_r_deg']):.3f} | {med(vals['me_t_m']):.4f} |")

P("\n## Pooled over seeds (medians over found objects; camera ATE: median over seeds)\n")
P("| input | objects found | median obj ATE m | median ME_r deg | median ME_t m | median camera ATE m |")
P("|---|---|---|---|---|---|")
for inp in INPUTS:
    allobjs = [o for n in SEEDS for o in data[inp][n][1].values()]
    vals = {k: [o[k] for o in allobjs if o[k] is not None] for k, _ in METRICS}
    cams = [data[inp][n][0] for n in SEEDS]
    P(f"| {inp} | {len(allobjs)} | {med(vals['ate_m']):.4f} | {med(vals['me_r_deg']):.3f} | "
      f"{med(vals['me_t_m']):.4f} | {med(cams):.4f} |")

def ratios_for(inp, refs, key):
    per_seed = {}
    for n in SEEDS:
        lr = []
        for g, o in data[inp][n][1].items():
            if not all(g in data[r][n][1] for r in refs):
                continue
            x = o[key]
            ys = [data[r][n][1][g][key] for r in refs]
            if x is None or any(y is None for y in ys) or x <= 0 or any(y <= 0 for y in ys):
                continue
            lr.append(math.log(x) - np.mean(np.log(ys)))
        per_seed[n] = lr
    return per_seed

def boot(per_seed):
    seeds = list(SEEDS)
    allv = [v for n in seeds for v in per_seed[n]]
    if not allv:
        return float("nan"), float("nan"), float("nan"), 0
    est = math.exp(np.mean(allv))
    bs = []
    for _ in range(NBOOT):
        pick = rng.choice(seeds, size=len(seeds), replace=True)
        v = [x for s in pick for x in per_seed[s]]
        if v:
            bs.append(math.exp(np.mean(v)))
    lo, hi = np.percentile(bs, [2.5, 97.5])
    return est, lo, hi, len(allv)

def cam_ratios(inp, refs):
    return {n: [math.log(data[inp][n][0]) - np.mean([math.log(data[r][n][0]) for r in refs])] for n in SEEDS}

def refs_of(inp):
    return FAMILY if inp not in FAMILY else [f for f in FAMILY if f != inp]

P(f"\n## Bias against the family (geometric mean of ratios over paired objects; 95 % bootstrap CI resampling seeds, {NBOOT} resamples)\n")
P("ratio = input / geometric mean of the reference; reference = rect, noise1, noise2 for the rigs, "
  "the other two members for family members (the floor rows). Paired object = found by the input and by every reference member.\n")
P("| input | reference | n obj | obj ATE bias [95 % CI] | ME_r bias [95 % CI] | ME_t bias [95 % CI] | camera ATE bias [95 % CI] |")
P("|---|---|---|---|---|---|---|")
for inp in INPUTS:
    refs = refs_of(inp)
    cells = []; nobj = None
    for key, _ in METRICS:
        est, lo, hi, cnt = boot(ratios_for(inp, refs, key))
        if key == "ate_m":
            nobj = cnt
        cells.append(f"{est:.2f} [{lo:.2f}, {hi:.2f}]")
    est, lo, hi, _ = boot(cam_ratios(inp, refs))
    cells.append(f"{est:.2f} [{lo:.2f}, {hi:.2f}]")
    P(f"| {inp} | {'/'.join(refs)} | {nobj} | " + " | ".join(cells) + " |")

P("\n## Per-seed object-ATE bias (geometric mean over the seed's paired objects; n in brackets)\n")
P("| seed | " + " | ".join(INPUTS) + " |")
P("|---|" + "---|" * len(INPUTS))
for n in SEEDS:
    c = []
    for inp in INPUTS:
        lr = ratios_for(inp, refs_of(inp), "ate_m")[n]
        c.append(f"{math.exp(np.mean(lr)):.2f} ({len(lr)})" if lr else "– (0)")
    P(f"| {n} | " + " | ".join(c) + " |")

P("\n## Camera ATE ratio per seed (input / geometric mean of reference)\n")
P("| seed | " + " | ".join(INPUTS) + " |")
P("|---|" + "---|" * len(INPUTS))
for n in SEEDS:
    P(f"| {n} | " + " | ".join(f"{math.exp(cam_ratios(inp, refs_of(inp))[n][0]):.2f}" for inp in INPUTS) + " |")

P("\n## Objects found by all three family members: how many the rigs also find\n")
P("| input | objects found | found by all 3 family | also found by input | found by input but not by all 3 family |")
P("|---|---|---|---|---|")
for inp in RIGS:
    a = b = c = t = 0
    for n in SEEDS:
        fam = set.intersection(*[set(data[f][n][1]) for f in FAMILY])
        mine = set(data[inp][n][1])
        a += len(fam); b += len(fam & mine); c += len(mine - fam); t += len(mine)
    P(f"| {inp} | {t} | {a} | {b} | {c} |")
P("\nFloor for the same count: objects found by the other two family members, and how many the member also finds\n")
P("| member | objects found | found by other two | also found by member |")
P("|---|---|---|---|")
for inp in FAMILY:
    others = [f for f in FAMILY if f != inp]
    a = b = t = 0
    for n in SEEDS:
        fam = set.intersection(*[set(data[f][n][1]) for f in others])
        a += len(fam); b += len(fam & set(data[inp][n][1])); t += len(data[inp][n][1])
    P(f"| {inp} | {t} | {a} | {b} |")

# ---- like-for-like with the floor: each rig against each PAIR of family members (floor rows compare 1 vs 2)
P("\n## Supplement: each rig against each pair of family members (same 1-vs-2 structure as the floor rows)\n")
P("| input | reference | n obj | obj ATE bias [95 % CI] | ME_r bias [95 % CI] | ME_t bias [95 % CI] | camera ATE bias [95 % CI] |")
P("|---|---|---|---|---|---|---|")
for inp in RIGS:
    for drop in FAMILY:
        refs = [f for f in FAMILY if f != drop]
        cells = []; nobj = None
        for key, _ in METRICS:
            est, lo, hi, cnt = boot(ratios_for(inp, refs, key))
            if key == "ate_m":
                nobj = cnt
            cells.append(f"{est:.2f} [{lo:.2f}, {hi:.2f}]")
        est, lo, hi, _ = boot(cam_ratios(inp, refs))
        cells.append(f"{est:.2f} [{lo:.2f}, {hi:.2f}]")
        P(f"| {inp} | {'/'.join(refs)} | {nobj} | " + " | ".join(cells) + " |")

text = "\n".join(out)
print(text)
open("/tmp/blur2/analysis.md", "w").write(text + "\n")
