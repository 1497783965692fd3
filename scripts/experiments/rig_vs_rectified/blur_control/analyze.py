#!/usr/bin/python3
"""Blur control: object metrics of blurred direct renderings vs the unblurred family."""
import json, math, sys
import numpy as np

SEEDS = [1, 3, 4, 5, 6, 7, 8, 9, 10]
INPUTS = {"rect": "s{n}", "noise1": "s{n}_noise1", "noise2": "s{n}_noise2",
          "blurA": "s{n}_blurA", "blurB": "s{n}_blurB"}
FAMILY = ["rect", "noise1", "noise2"]
METRICS = [("ate_m", "obj ATE m"), ("me_r_deg", "ME_r deg"), ("me_t_m", "ME_t m")]
R = "/tmp/blur/R"
NBOOT = 2000
rng = np.random.default_rng(12345)

def load(inp, n):
    d = json.load(open(f"{R}/{INPUTS[inp].format(n=n)}/metrics.json"))
    objs = {}
    for o in d["objects"]["per_object"]:
        if o["found"]:
            objs[o["gt_object"]] = o
    return d["camera"]["ate_m"], objs, len(d["objects"]["per_object"])

data = {inp: {n: load(inp, n) for n in SEEDS} for inp in INPUTS}

def gmean(v):
    v = np.asarray(v, float)
    return float(np.exp(np.mean(np.log(v))))

def med(v):
    return float(np.median(v)) if len(v) else float("nan")

out = []
P = out.append

# ---- per-seed table
P("## Per-seed results\n")
P("| seed | input | camera ATE m | objects found / gt | median obj ATE m | median ME_r deg | median ME_t m |")
P("|---|---|---|---|---|---|---|")
for n in SEEDS:
    for inp in INPUTS:
        cam, objs, ngt = data[inp][n]
        vals = {k: [o[k] for o in objs.values() if o[k] is not None] for k, _ in METRICS}
        P(f"| {n} | {inp} | {cam:.4f} | {len(objs)} / {ngt} | {med(vals['ate_m']):.4f} | "
          f"{med(vals['me_r_deg']):.3f} | {med(vals['me_t_m']):.4f} |")

# ---- pooled table
P("\n## Pooled over seeds (medians over found objects; camera ATE: median over seeds)\n")
P("| input | objects found | median obj ATE m | median ME_r deg | median ME_t m | median camera ATE m |")
P("|---|---|---|---|---|---|")
for inp in INPUTS:
    allobjs = [o for n in SEEDS for o in data[inp][n][1].values()]
    vals = {k: [o[k] for o in allobjs if o[k] is not None] for k, _ in METRICS}
    cams = [data[inp][n][0] for n in SEEDS]
    P(f"| {inp} | {len(allobjs)} | {med(vals['ate_m']):.4f} | {med(vals['me_r_deg']):.3f} | "
      f"{med(vals['me_t_m']):.4f} | {med(cams):.4f} |")

# ---- paired biases
def ratios_for(inp, refs, key):
    """per seed: list of log ratios input / gmean(refs) over objects found by input and all refs."""
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
    seeds = [n for n in SEEDS]
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

P("\n## Bias against the family (geometric mean of ratios; 95 % bootstrap CI over seeds, "
  f"{NBOOT} resamples)\n")
P("Inputs blurA/blurB/rect-family members: ratio = input / geometric mean of the reference; "
  "reference = rect, noise1, noise2 for blurred inputs, the other two members for family members (the floor).\n")
P("| input | reference | n obj | obj ATE bias [95 % CI] | ME_r bias [95 % CI] | ME_t bias [95 % CI] | camera ATE bias [95 % CI] |")
P("|---|---|---|---|---|---|---|")
rows = []
for inp in ["blurA", "blurB"] + FAMILY:
    refs = FAMILY if inp not in FAMILY else [f for f in FAMILY if f != inp]
    cells = []
    nobj = None
    for key, _ in METRICS:
        est, lo, hi, cnt = boot(ratios_for(inp, refs, key))
        if key == "ate_m":
            nobj = cnt
        cells.append(f"{est:.2f} [{lo:.2f}, {hi:.2f}]")
    est, lo, hi, _ = boot(cam_ratios(inp, refs))
    cells.append(f"{est:.2f} [{lo:.2f}, {hi:.2f}]")
    P(f"| {inp} | {'/'.join(refs)} | {nobj} | " + " | ".join(cells) + " |")

P("\n## Camera ATE ratio per seed (input / geometric mean of reference)\n")
P("| seed | " + " | ".join(["blurA", "blurB"] + FAMILY) + " |")
P("|---|" + "---|" * 5)
for n in SEEDS:
    c = []
    for inp in ["blurA", "blurB"] + FAMILY:
        refs = FAMILY if inp not in FAMILY else [f for f in FAMILY if f != inp]
        c.append(f"{math.exp(cam_ratios(inp, refs)[n][0]):.2f}")
    P(f"| {n} | " + " | ".join(c) + " |")

# found-by-family objects lost by the blurred inputs
P("\n## Objects found by all three family members: how many the blurred inputs also find\n")
P("| input | found by all 3 family | also found by input | found by input but not by all 3 family |")
P("|---|---|---|---|")
for inp in ["blurA", "blurB"]:
    a = b = c = 0
    for n in SEEDS:
        fam = set.intersection(*[set(data[f][n][1]) for f in FAMILY])
        mine = set(data[inp][n][1])
        a += len(fam); b += len(fam & mine); c += len(mine - fam)
    P(f"| {inp} | {a} | {b} | {c} |")
P("\nFloor for the same count: objects found by the other two family members, and how many the member also finds\n")
P("| member | found by other two | also found by member |")
P("|---|---|---|")
for inp in FAMILY:
    others = [f for f in FAMILY if f != inp]
    a = b = 0
    for n in SEEDS:
        fam = set.intersection(*[set(data[f][n][1]) for f in others])
        a += len(fam); b += len(fam & set(data[inp][n][1]))
    P(f"| {inp} | {a} | {b} |")

text = "\n".join(out)
print(text)
open("/tmp/blur/analysis.md", "w").write(text + "\n")
