#!/usr/bin/python3
"""Rig control: object metrics of rectified-back distorted rigs vs the direct-rendering family.
Family runs: /tmp/blur/R (the same binary); rig runs: /tmp/blur2/R."""
import math, os
import numpy as np
from family_bias import FAMILY, HEADER, Runs, refs_of

ALLSEEDS = [1, 3, 4, 5, 6, 7, 8, 9, 10]
PATHS = {"rect": "/tmp/blur/R/s{n}", "noise1": "/tmp/blur/R/s{n}_noise1", "noise2": "/tmp/blur/R/s{n}_noise2",
         "radtan": "/tmp/blur2/R/s{n}_radtan", "equidistant": "/tmp/blur2/R/s{n}_equidistant"}
RIGS = ["radtan", "equidistant"]
INPUTS = RIGS + FAMILY
# Seeds with both rig runs present.
SEEDS = [n for n in ALLSEEDS if all(os.path.exists(PATHS[r].format(n=n) + "/metrics.json") for r in RIGS)]
runs = Runs({inp: PATHS[inp] for inp in INPUTS}, SEEDS)

out = [f"Seeds analysed: {SEEDS}\n"] + runs.per_seed_table(INPUTS) + runs.pooled_table(INPUTS)
P = out.append
P(f"\n## Bias against the family (geometric mean of ratios over paired objects; 95 % bootstrap CI resampling seeds, {runs.nboot} resamples)\n")
P("ratio = input / geometric mean of the reference; reference = rect, noise1, noise2 for the rigs, "
  "the other two members for family members (the floor rows). Paired object = found by the input and by every reference member.\n")
out += HEADER
for inp in INPUTS:
    P(runs.bias_row(inp, refs_of(inp)))

P("\n## Per-seed object-ATE bias (geometric mean over the seed's paired objects; n in brackets)\n")
P("| seed | " + " | ".join(INPUTS) + " |")
P("|---|" + "---|" * len(INPUTS))
for n in SEEDS:
    c = []
    for inp in INPUTS:
        lr = runs.ratios_for(inp, refs_of(inp), "ate_m")[n]
        c.append(f"{math.exp(np.mean(lr)):.2f} ({len(lr)})" if lr else "– (0)")
    P(f"| {n} | " + " | ".join(c) + " |")

P("\n## Camera ATE ratio per seed (input / geometric mean of reference)\n")
P("| seed | " + " | ".join(INPUTS) + " |")
P("|---|" + "---|" * len(INPUTS))
for n in SEEDS:
    P(f"| {n} | " + " | ".join(f"{runs.cam_ratio(inp, n):.2f}" for inp in INPUTS) + " |")

P("\n## Objects found by all three family members: how many the rigs also find\n")
P("| input | objects found | found by all 3 family | also found by input | found by input but not by all 3 family |")
P("|---|---|---|---|---|")
for inp in RIGS:
    a = b = c = t = 0
    for n in SEEDS:
        fam, mine = runs.found_by_all(FAMILY, n), set(runs.data[inp][n][1])
        a += len(fam); b += len(fam & mine); c += len(mine - fam); t += len(mine)
    P(f"| {inp} | {t} | {a} | {b} | {c} |")
P("\nFloor for the same count: objects found by the other two family members, and how many the member also finds\n")
P("| member | objects found | found by other two | also found by member |")
P("|---|---|---|---|")
for inp in FAMILY:
    a = b = t = 0
    for n in SEEDS:
        fam = runs.found_by_all(refs_of(inp), n)
        a += len(fam); b += len(fam & set(runs.data[inp][n][1])); t += len(runs.data[inp][n][1])
    P(f"| {inp} | {t} | {a} | {b} |")

# Like for like with the floor rows (one against two): each rig against each pair of members.
P("\n## Supplement: each rig against each pair of family members (same 1-vs-2 structure as the floor rows)\n")
out += HEADER
for inp in RIGS:
    for drop in FAMILY:
        P(runs.bias_row(inp, [f for f in FAMILY if f != drop]))

text = "\n".join(out)
print(text)
open("/tmp/blur2/analysis.md", "w").write(text + "\n")
