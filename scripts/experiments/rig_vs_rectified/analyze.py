#!/usr/bin/python3
"""Tables of docs/experiments/2026-12-06-generated-rig-vs-rectified.md section 2, re-run with the
frozen binary, plus the periphery test of the equidistant rig (issue 37).

Reads /tmp/r37/R/s<n>_<input>/metrics.json and the sequences /tmp/r37/s<n>/ (observations.csv,
gt_landmarks.csv, camera.txt). Writes the tables to stdout (markdown).

Usage: /usr/bin/python3 /tmp/r37/analyze.py [--root /tmp/r37] [--seeds 1-10]
"""
import argparse
import csv
import json
import math
import os
from collections import defaultdict

import numpy as np

MAIN = ["rect", "noise1", "noise2", "radtan", "equidistant"]
OWN = ["radtan_own", "equidistant_own"]
LABEL = {
    "rect": "rectified rendering",
    "noise1": "+-1 grey noise, seed 1",
    "noise2": "+-1 grey noise, seed 2",
    "radtan": "radtan rig, rectified back",
    "equidistant": "equidistant rig, rectified back",
}
FAMILY = ["rect", "noise1", "noise2"]
OBJ_METRICS = [("ate_m", "object ATE"), ("me_r_deg", "ME_r"), ("me_t_m", "ME_t")]
LOST_M = 1.0  # the doc's rule: a seed is dropped when any main input has camera ATE > 1 m


def load(root, seed, inp):
    p = os.path.join(root, "R", f"s{seed}_{inp}", "metrics.json")
    if not os.path.exists(p):
        return None
    with open(p) as f:
        return json.load(f)


def found_objects(m):
    return [o for o in m.get("objects", {}).get("per_object", []) if o.get("found")]


def med(xs):
    xs = [x for x in xs if x is not None and not (isinstance(x, float) and math.isnan(x))]
    return float(np.median(xs)) if xs else float("nan")


def fmt(x, nd=3):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    return f"{x:.{nd}f}"


def pct(x):
    return "—" if math.isnan(x) else f"{x * 100:+.0f}%"


def read_camera(path):
    cam = {}
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            k, v = line.split()
            cam[k] = float(v)
    return cam


def object_positions(seqdir):
    """Per ground-truth object: where its landmarks are seen in the left image (generator's
    observations.csv, the same scene for every input of a seed). Returns {object: dict} with the
    median of |u-cx|/fx, of the normalized radius sqrt(((u-cx)/fx)^2 + ((v-cy)/fy)^2), and the
    fraction of observations with |u-cx|/fx > 0.5."""
    cam = read_camera(os.path.join(seqdir, "camera.txt"))
    lm_obj = {}
    with open(os.path.join(seqdir, "gt_landmarks.csv")) as f:
        for r in csv.DictReader(f):
            lm_obj[int(r["landmark"])] = int(r["object"])
    xs = defaultdict(list)
    rs = defaultdict(list)
    with open(os.path.join(seqdir, "observations.csv")) as f:
        rd = csv.reader(f)
        next(rd)
        for r in rd:
            o = lm_obj[int(r[1])]
            if o == 0:
                continue
            x = (float(r[2]) - cam["cx"]) / cam["fx"]
            y = (float(r[3]) - cam["cy"]) / cam["fy"]
            xs[o].append(abs(x))
            rs[o].append(math.hypot(x, y))
    out = {}
    for o in xs:
        a = np.array(xs[o])
        out[o] = {
            "x": float(np.median(a)),
            "r": float(np.median(rs[o])),
            "frac_x_gt_0.5": float(np.mean(a > 0.5)),
            "n_obs": len(a),
        }
    return out


def spearman(a, b):
    ra = np.argsort(np.argsort(a)).astype(float)
    rb = np.argsort(np.argsort(b)).astype(float)
    ra -= ra.mean()
    rb -= rb.mean()
    return float((ra * rb).sum() / math.sqrt((ra * ra).sum() * (rb * rb).sum()))


def perm_p_spearman(a, b, n=20000, rng=None):
    rng = rng or np.random.default_rng(0)
    r0 = spearman(a, b)
    cnt = 0
    b = np.array(b)
    for _ in range(n):
        if abs(spearman(a, rng.permutation(b))) >= abs(r0) - 1e-12:
            cnt += 1
    return r0, (cnt + 1) / (n + 1)


def perm_p_diff(near, far, n=20000, rng=None):
    """Two-sided permutation p of mean(far) - mean(near) (log ratios)."""
    rng = rng or np.random.default_rng(1)
    near = np.asarray(near)
    far = np.asarray(far)
    d0 = far.mean() - near.mean()
    allv = np.concatenate([near, far])
    k = len(far)
    cnt = 0
    for _ in range(n):
        p = rng.permutation(allv)
        if abs(p[:k].mean() - p[k:].mean()) >= abs(d0) - 1e-12:
            cnt += 1
    return float(d0), (cnt + 1) / (n + 1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--root", default="/tmp/r37")
    ap.add_argument("--seeds", default="1-10")
    args = ap.parse_args()
    lo, hi = (int(x) for x in args.seeds.split("-"))
    root = args.root

    data = {}
    for s in range(lo, hi + 1):
        row = {inp: load(root, s, inp) for inp in MAIN + OWN}
        if all(row[i] is not None for i in MAIN):
            data[s] = row
    seeds = sorted(data)
    print(f"Seeds with all five main runs: {seeds}\n")

    # ---- per-seed table
    print("### Per seed\n")
    print("| seed | input | camera ATE (m) | path (m, gt) | clustering accuracy | objects found | object ATE median (m) | ME_r median (deg) | ME_t median (m) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for s in seeds:
        for inp in MAIN:
            m = data[s][inp]
            cam = m["camera"]
            fo = found_objects(m)
            n_all = len(m["objects"]["per_object"])
            ate = cam["ate_m"]
            ate_s = f"**{ate:.2f}**" if ate > LOST_M else f"{ate:.4f}"
            print(f"| {s} | {LABEL[inp]} | {ate_s} | {cam['path_length_m']:.1f} ({cam['gt_path_length_m']:.1f}) | "
                  f"{m['clustering']['accuracy']:.3f} | {len(fo)} of {n_all} | "
                  f"{fmt(med([o['ate_m'] for o in fo]))} | {fmt(med([o['me_r_deg'] for o in fo]))} | "
                  f"{fmt(med([o['me_t_m'] for o in fo]))} |")
        own = [data[s][i]["camera"]["ate_m"] if data[s][i] else float("nan") for i in OWN]
        print(f"| {s} | cslam's own rectification, radtan / equidistant (camera only) | "
              f"{own[0]:.4f} / {own[1]:.4f} | | | | | | |")
    print()

    lost = {s: [i for i in MAIN if data[s][i]["camera"]["ate_m"] > LOST_M] for s in seeds}
    lost_own = {s: [i for i in OWN if data[s][i] and data[s][i]["camera"]["ate_m"] > LOST_M] for s in seeds}
    kept = [s for s in seeds if not lost[s]]
    for s in seeds:
        if lost[s] or lost_own[s]:
            print(f"- seed {s}: camera ATE > {LOST_M} m on {lost[s] + lost_own[s]}")
    print(f"\nKept seeds (no main input lost the camera): {kept}\n")

    # ---- pooled medians
    print("### Pooled medians over the kept seeds\n")
    print("| input | camera ATE median (m) | clustering accuracy median | objects found | object ATE median (m) | ME_r median (deg) | ME_t median (m) | objects <= 20 m: n, ATE median, ME_t median |")
    print("|---|---|---|---|---|---|---|---|")
    pooled = {}
    for inp in MAIN + OWN:
        runs = [data[s][inp] for s in kept if data[s][inp]]
        cam = med([m["camera"]["ate_m"] for m in runs])
        if inp in OWN:
            print(f"| {inp} (camera only) | {cam:.4f} | | | | | | |")
            pooled[inp] = {"cam": cam}
            continue
        fo = [o for m in runs for o in found_objects(m)]
        near = [o for o in fo if o["median_distance_m"] <= 20]
        pooled[inp] = {"cam": cam, "acc": med([m["clustering"]["accuracy"] for m in runs]),
                       "n": len(fo)}
        for k, _ in OBJ_METRICS:
            pooled[inp][k] = med([o[k] for o in fo])
        print(f"| {inp} | {cam:.4f} | {pooled[inp]['acc']:.3f} | {len(fo)} | {pooled[inp]['ate_m']:.3f} | "
              f"{pooled[inp]['me_r_deg']:.3f} | {pooled[inp]['me_t_m']:.4f} | "
              f"{len(near)}, {fmt(med([o['ate_m'] for o in near]))}, {fmt(med([o['me_t_m'] for o in near]), 4)} |")
    print()

    # ---- relative to the rectified family
    fam_runs = [data[s][i] for s in kept for i in FAMILY]
    fam_fo = [o for m in fam_runs for o in found_objects(m)]
    fam = {"cam": med([m["camera"]["ate_m"] for m in fam_runs]),
           "acc": med([m["clustering"]["accuracy"] for m in fam_runs])}
    for k, _ in OBJ_METRICS:
        fam[k] = med([o[k] for o in fam_fo])
    print("### Pooled median relative to the rectified family (rect + noise1 + noise2 pooled)\n")
    print("| input | camera ATE | clustering accuracy | object ATE | ME_r | ME_t |")
    print("|---|---|---|---|---|---|")
    print(f"| rectified family, value | {fam['cam']:.5f} | {fam['acc']:.4f} | {fam['ate_m']:.4f} | "
          f"{fam['me_r_deg']:.4f} | {fam['me_t_m']:.5f} |")
    for inp in MAIN + OWN:
        p = pooled[inp]
        cells = [pct(p["cam"] / fam["cam"] - 1)]
        if inp in OWN:
            cells += ["", "", "", ""]
        else:
            cells += [pct(p["acc"] / fam["acc"] - 1)] + [pct(p[k] / fam[k] - 1) for k, _ in OBJ_METRICS]
        print(f"| {inp} | " + " | ".join(cells) + " |")
    print()

    # ---- paired against the rectified run
    def paired(inp, ref="rect", seeds_=None):
        seeds_ = kept if seeds_ is None else seeds_
        cam_r = [data[s][inp]["camera"]["ate_m"] / data[s][ref]["camera"]["ate_m"] for s in seeds_ if data[s][inp]]
        obj = {k: [] for k, _ in OBJ_METRICS}
        npair = 0
        if inp not in OWN:
            for s in seeds_:
                a = {o["gt_object"]: o for o in found_objects(data[s][ref])}
                b = {o["gt_object"]: o for o in found_objects(data[s][inp])}
                for g in sorted(set(a) & set(b)):
                    npair += 1
                    for k, _ in OBJ_METRICS:
                        obj[k].append(b[g][k] / a[g][k])
        return cam_r, obj, npair

    def bias_scatter(r):
        r = np.asarray(r, float)
        if len(r) == 0:
            return "—"
        return f"{math.exp(np.mean(np.log(r))):.2f}, {np.median(np.abs(r - 1)) * 100:.0f}%"

    print("### Paired against the rectified run (bias = geometric mean of input/rect, scatter = median |ratio - 1|)\n")
    print("| input against the rectified run | camera ATE: bias, scatter (runs) | object ATE: bias, scatter | ME_r: bias, scatter | ME_t: bias, scatter | objects paired |")
    print("|---|---|---|---|---|---|")
    for inp in ["noise1", "noise2", "radtan", "equidistant"] + OWN:
        cam_r, obj, npair = paired(inp)
        cells = [f"{bias_scatter(cam_r)} ({len(cam_r)})"]
        if inp in OWN:
            cells += ["", "", "", ""]
        else:
            cells += [bias_scatter(obj[k]) for k, _ in OBJ_METRICS] + [str(npair)]
        print(f"| {inp} | " + " | ".join(cells) + " |")
    print()
    # noise1 vs noise2 as another pair of family members
    print("Family members against each other (noise2 / noise1):", end=" ")
    cam_r, obj, npair = paired("noise2", ref="noise1")
    print(f"camera {bias_scatter(cam_r)}; " + "; ".join(f"{lab} {bias_scatter(obj[k])}" for k, lab in OBJ_METRICS)
          + f"; {npair} objects\n")

    # ---- paired against the family's geometric mean (a less noisy reference), seed-bootstrap CIs
    def fam_ref(s, g, k, members):
        vals = []
        for i in members:
            d = {o["gt_object"]: o for o in found_objects(data[s][i])}
            if g not in d:
                return None
            vals.append(d[g][k])
        return math.exp(np.mean(np.log(vals)))

    def ratios_vs(inp, members):
        out = []  # (seed, {metric: ratio})
        for s in kept:
            b = {o["gt_object"]: o for o in found_objects(data[s][inp])}
            for g in b:
                r = {}
                for k, _ in OBJ_METRICS:
                    ref = fam_ref(s, g, k, members)
                    if ref is None:
                        break
                    r[k] = b[g][k] / ref
                else:
                    out.append((s, r))
        return out

    rng = np.random.default_rng(7)

    def boot_ci(rows, k, nb=4000):
        by = defaultdict(list)
        for s, r in rows:
            by[s].append(math.log(r[k]))
        ss = sorted(by)
        est = math.exp(np.mean([v for s in ss for v in by[s]]))
        bs = []
        for _ in range(nb):
            pick = rng.choice(ss, len(ss))
            v = [x for s in pick for x in by[s]]
            bs.append(np.mean(v))
        lo_, hi_ = np.percentile(bs, [2.5, 97.5])
        return est, math.exp(lo_), math.exp(hi_)

    print("### Paired against the family's geometric mean per object (objects found by all reference runs); "
          "bias with a 95 % bootstrap interval over seeds (4000 resamples of the kept seeds), scatter = median |ratio - 1|\n")
    print("| input | reference | objects | object ATE: bias [95 % CI], scatter | ME_r: bias [CI], scatter | ME_t: bias [CI], scatter |")
    print("|---|---|---|---|---|---|")
    combos = [("rect", ["noise1", "noise2"]), ("noise1", ["rect", "noise2"]), ("noise2", ["rect", "noise1"]),
              ("radtan", FAMILY), ("equidistant", FAMILY), ("radtan", ["noise1", "noise2"]), ("equidistant", ["noise1", "noise2"])]
    for inp, members in combos:
        rows = ratios_vs(inp, members)
        cells = []
        for k, _ in OBJ_METRICS:
            est, lo_, hi_ = boot_ci(rows, k)
            sc = np.median([abs(r[k] - 1) for _, r in rows]) * 100
            cells.append(f"{est:.2f} [{lo_:.2f}, {hi_:.2f}], {sc:.0f}%")
        print(f"| {inp} | geo. mean of {'+'.join(members)} | {len(rows)} | " + " | ".join(cells) + " |")
    print()
    # camera, same idea
    print("Camera ATE against the family's geometric mean per seed (runs; bootstrap over seeds):", end=" ")
    parts = []
    for inp, members in [("rect", ["noise1", "noise2"]), ("noise1", ["rect", "noise2"]), ("noise2", ["rect", "noise1"]),
                         ("radtan", FAMILY), ("equidistant", FAMILY), ("radtan_own", FAMILY), ("equidistant_own", FAMILY)]:
        lr = np.array([math.log(data[s][inp]["camera"]["ate_m"]) - np.mean([math.log(data[s][i]["camera"]["ate_m"]) for i in members]) for s in kept])
        bs = [np.mean(rng.choice(lr, len(lr))) for _ in range(4000)]
        lo_, hi_ = np.percentile(bs, [2.5, 97.5])
        parts.append(f"{inp} {math.exp(lr.mean()):.2f} [{math.exp(lo_):.2f}, {math.exp(hi_):.2f}]")
    print("; ".join(parts) + "\n")

    # ---- objects found: which gt objects, overlap
    print("### Objects found per input (kept seeds)\n")
    for inp in MAIN:
        fo = [(s, o["gt_object"]) for s in kept for o in found_objects(data[s][inp])]
        both = [(s, g) for (s, g) in fo if g in {o["gt_object"] for o in found_objects(data[s]["rect"])}]
        print(f"- {inp}: {len(fo)} found, {len(both)} of them also found by rect")
    print()

    # ---- leave-one-seed-out sensitivity of the relative figures
    print("### Leave-one-seed-out range of the pooled relative figures (min … max over dropping one kept seed)\n")
    print("| input | camera ATE | object ATE | ME_r | ME_t |")
    print("|---|---|---|---|---|")
    loo = {inp: defaultdict(list) for inp in MAIN}
    for drop in kept:
        ks = [s for s in kept if s != drop]
        fr = [data[s][i] for s in ks for i in FAMILY]
        ffo = [o for m in fr for o in found_objects(m)]
        f = {"cam": med([m["camera"]["ate_m"] for m in fr])}
        for k, _ in OBJ_METRICS:
            f[k] = med([o[k] for o in ffo])
        for inp in MAIN:
            runs = [data[s][inp] for s in ks]
            fo = [o for m in runs for o in found_objects(m)]
            loo[inp]["cam"].append(med([m["camera"]["ate_m"] for m in runs]) / f["cam"] - 1)
            for k, _ in OBJ_METRICS:
                loo[inp][k].append(med([o[k] for o in fo]) / f[k] - 1)
    for inp in MAIN:
        cells = [f"{pct(min(loo[inp][k]))} … {pct(max(loo[inp][k]))}" for k in ["cam", "ate_m", "me_r_deg", "me_t_m"]]
        print(f"| {inp} | " + " | ".join(cells) + " |")
    print()

    # ---- periphery analysis
    print("## Periphery: paired ratio (input / rect) against where the object is in the image\n")
    pos = {s: object_positions(os.path.join(root, f"s{s}")) for s in kept}
    rows = defaultdict(list)  # inp -> list of (seed, obj, x, r, frac, {metric: ratio}, dist)
    for s in kept:
        a = {o["gt_object"]: o for o in found_objects(data[s]["rect"])}
        for inp in ["noise1", "noise2", "radtan", "equidistant"]:
            b = {o["gt_object"]: o for o in found_objects(data[s][inp])}
            for g in sorted(set(a) & set(b)):
                p = pos[s][g]
                rows[inp].append((s, g, p["x"], p["r"], p["frac_x_gt_0.5"],
                                  {k: b[g][k] / a[g][k] for k, _ in OBJ_METRICS}, a[g]["median_distance_m"]))

    print("Per object (equidistant / rect), the position from the generator's observations of the "
          "object's landmarks (all frames), x = median |u - cx| / fx, rad = median normalized radius:\n")
    print("| seed | gt object | x | rad | share of obs with x > 0.5 | median distance (m) | ATE ratio | ME_r ratio | ME_t ratio |")
    print("|---|---|---|---|---|---|---|---|---|")
    for (s, g, x, r, fr, rat, d) in sorted(rows["equidistant"], key=lambda t: t[2]):
        print(f"| {s} | {g} | {x:.3f} | {r:.3f} | {fr:.2f} | {d:.1f} | {rat['ate_m']:.2f} | {rat['me_r_deg']:.2f} | {rat['me_t_m']:.2f} |")
    print()

    for posname, idx in [("x = median |u-cx|/fx", 2), ("normalized radius", 3)]:
        print(f"### Split at the median of {posname} (per input's paired objects)\n")
        print("| input | n near / far | split at | metric | near: bias (geo. mean), median ratio | far: bias, median ratio | far/near bias | perm. p (log ratio, far vs near) | Spearman rho(position, log ratio), perm. p |")
        print("|---|---|---|---|---|---|---|---|---|")
        for inp in ["equidistant", "radtan", "noise1", "noise2"]:
            rr = rows[inp]
            px = np.array([t[idx] for t in rr])
            cut = float(np.median(px))
            near_i = px <= cut
            for k, lab in OBJ_METRICS:
                lr = np.log(np.array([t[5][k] for t in rr]))
                n_, f_ = lr[near_i], lr[~near_i]
                d0, p = perm_p_diff(n_, f_)
                rho, prho = perm_p_spearman(px, lr)
                print(f"| {inp} | {len(n_)} / {len(f_)} | {cut:.3f} | {lab} | {math.exp(n_.mean()):.2f}, {math.exp(np.median(n_)):.2f} | "
                      f"{math.exp(f_.mean()):.2f}, {math.exp(np.median(f_)):.2f} | {math.exp(d0):.2f} | {p:.2f} | {rho:+.2f}, {prho:.2f} |")
        print()

    # fixed threshold: any substantial time in the outer half of the field
    print("### Fixed split: objects whose median |u-cx|/fx > 0.5 (outer half of the half-width; "
          "equidistant sampling there <= 0.8 of the pinhole's radially)\n")
    print("| input | metric | n centre / periphery | centre bias | periphery bias | periphery/centre | perm. p |")
    print("|---|---|---|---|---|---|---|")
    for inp in ["equidistant", "radtan", "noise1", "noise2"]:
        rr = rows[inp]
        px = np.array([t[2] for t in rr])
        far_i = px > 0.5
        for k, lab in OBJ_METRICS:
            lr = np.log(np.array([t[5][k] for t in rr]))
            if far_i.sum() == 0 or (~far_i).sum() == 0:
                print(f"| {inp} | {lab} | {(~far_i).sum()} / {far_i.sum()} | — | — | — | — |")
                continue
            d0, p = perm_p_diff(lr[~far_i], lr[far_i])
            print(f"| {inp} | {lab} | {(~far_i).sum()} / {far_i.sum()} | {math.exp(lr[~far_i].mean()):.2f} | "
                  f"{math.exp(lr[far_i].mean()):.2f} | {math.exp(d0):.2f} | {p:.2f} |")
    print()

    # position vs distance (confound check)
    rr = rows["equidistant"]
    px = np.array([t[2] for t in rr])
    dd = np.array([t[6] for t in rr])
    print(f"Confound check (equidistant pairs): Spearman rho(x, median distance) = {spearman(px, dd):+.2f}; "
          f"x over the paired objects: median {np.median(px):.3f}, range {px.min():.3f} … {px.max():.3f}\n")

    # all found objects (not only paired): pooled medians by position, rect vs equidistant
    print("### Unpaired: pooled medians of found objects by position (x split at 0.35), rect vs equidistant vs family\n")
    print("| input | centre n, ATE, ME_r, ME_t | periphery n, ATE, ME_r, ME_t |")
    print("|---|---|---|")
    for inp in MAIN:
        c, f = [], []
        for s in kept:
            for o in found_objects(data[s][inp]):
                (f if pos[s][o["gt_object"]]["x"] > 0.35 else c).append(o)
        def cell(lst):
            return f"{len(lst)}, {fmt(med([o['ate_m'] for o in lst]))}, {fmt(med([o['me_r_deg'] for o in lst]))}, {fmt(med([o['me_t_m'] for o in lst]), 4)}"
        print(f"| {inp} | {cell(c)} | {cell(f)} |")
    print()


if __name__ == "__main__":
    main()
