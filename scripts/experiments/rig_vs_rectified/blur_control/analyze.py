#!/usr/bin/python3
"""Blur control: object metrics of blurred direct renderings vs the unblurred family."""
from family_bias import FAMILY, HEADER, Runs, refs_of

R = "/tmp/blur/R"
SEEDS = [1, 3, 4, 5, 6, 7, 8, 9, 10]
NAMES = {"rect": "s{n}", "noise1": "s{n}_noise1", "noise2": "s{n}_noise2",
         "blurA": "s{n}_blurA", "blurB": "s{n}_blurB"}
BLURRED = ["blurA", "blurB"]
runs = Runs({inp: f"{R}/{name}" for inp, name in NAMES.items()}, SEEDS)

out = runs.per_seed_table(NAMES) + runs.pooled_table(NAMES)
P = out.append
P(f"\n## Bias against the family (geometric mean of ratios; 95 % bootstrap CI over seeds, {runs.nboot} resamples)\n")
P("Inputs blurA/blurB/rect-family members: ratio = input / geometric mean of the reference; "
  "reference = rect, noise1, noise2 for blurred inputs, the other two members for family members (the floor).\n")
out += HEADER
for inp in BLURRED + FAMILY:
    P(runs.bias_row(inp, refs_of(inp)))

P("\n## Camera ATE ratio per seed (input / geometric mean of reference)\n")
P("| seed | " + " | ".join(BLURRED + FAMILY) + " |")
P("|---|" + "---|" * 5)
for n in SEEDS:
    P(f"| {n} | " + " | ".join(f"{runs.cam_ratio(inp, n):.2f}" for inp in BLURRED + FAMILY) + " |")

P("\n## Objects found by all three family members: how many the blurred inputs also find\n")
P("| input | found by all 3 family | also found by input | found by input but not by all 3 family |")
P("|---|---|---|---|")
for inp in BLURRED:
    a = b = c = 0
    for n in SEEDS:
        fam, mine = runs.found_by_all(FAMILY, n), set(runs.data[inp][n][1])
        a += len(fam); b += len(fam & mine); c += len(mine - fam)
    P(f"| {inp} | {a} | {b} | {c} |")
P("\nFloor for the same count: objects found by the other two family members, and how many the member also finds\n")
P("| member | found by other two | also found by member |")
P("|---|---|---|")
for inp in FAMILY:
    a = b = 0
    for n in SEEDS:
        fam = runs.found_by_all(refs_of(inp), n)
        a += len(fam); b += len(fam & set(runs.data[inp][n][1]))
    P(f"| {inp} | {a} | {b} |")

text = "\n".join(out)
print(text)
open("/tmp/blur/analysis.md", "w").write(text + "\n")
