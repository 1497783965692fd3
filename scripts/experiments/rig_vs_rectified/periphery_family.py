#!/usr/bin/python3
"""Per-object periphery split with the family's geometric mean as reference (supplement to analyze.py)."""
import json, math, os, sys
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import analyze as A
ROOT = os.environ.get("WORK", "/tmp/r37")  # driver.sh's working folder
K = [1, 3, 4, 5, 6, 7, 8, 9, 10]
def fo(s, i):
    m = json.load(open(f'{ROOT}/R/s{s}_{i}/metrics.json')); return {o['gt_object']: o for o in m['objects']['per_object'] if o['found']}
pos = {s: A.object_positions(f'{ROOT}/s{s}') for s in K}
print("| input | reference | objects | metric | centre (x <= median) bias | periphery (x > median) bias | periphery/centre | perm. p | Spearman rho(x, log ratio), p |")
print("|---|---|---|---|---|---|---|---|---|")
for inp, ref in [('equidistant', ['rect', 'noise1', 'noise2']), ('radtan', ['rect', 'noise1', 'noise2']),
                 ('rect', ['noise1', 'noise2']), ('noise1', ['rect', 'noise2']), ('noise2', ['rect', 'noise1'])]:
    xs, L = [], []
    for s in K:
        b = fo(s, inp); R = [fo(s, i) for i in ref]
        for g in b:
            if all(g in r for r in R):
                xs.append(pos[s][g]['x'])
                L.append([math.log(b[g][k]) - np.mean([math.log(r[g][k]) for r in R]) for k in ['ate_m', 'me_r_deg', 'me_t_m']])
    xs = np.array(xs); L = np.array(L); cut = np.median(xs); far = xs > cut
    for j, lab in enumerate(['object ATE', 'ME_r', 'ME_t']):
        d, p = A.perm_p_diff(L[~far, j], L[far, j], n=10000)
        rho, pr = A.perm_p_spearman(xs, L[:, j], n=10000)
        print(f"| {inp} | {'+'.join(ref)} | {len(xs)} | {lab} | {math.exp(L[~far, j].mean()):.2f} | {math.exp(L[far, j].mean()):.2f} | {math.exp(d):.2f} | {p:.2f} | {rho:+.2f}, {pr:.2f} |")
