#!/usr/bin/python3
"""Per-frame version of the periphery test (supplement to analyze.py).

For every found object of a run, recompute the per-frame-pair motion errors (docs/evaluation.md:
H = X_k X_(k-1)^-1 in the camera frame at k-1, ME_r = angle(R_gt^T R_est), ME_t = |H_est c -
H_gt c| with c the true object origin at k-1) from objects/<cluster>.txt (+ _frames.txt),
camera_trajectory.txt, camera_trajectory_gt.txt and objects_gt/<gt>.txt, check their means against
metrics.json, and pair them frame by frame between an input and the rectified run. Each pair is
placed in the image by the median |u - cx| / fx of the ground-truth object's landmarks observed
(observations.csv) at frame k.

Usage: /usr/bin/python3 perframe.py [--root /tmp/r37] [--seeds 1,3,4,5,6,7,8,9,10]
"""
import argparse
import csv
import json
import math
import os
from collections import defaultdict

import numpy as np


def read_kitti(path):
    out = []
    with open(path) as f:
        for line in f:
            v = [float(x) for x in line.split()]
            if len(v) != 12:
                continue
            T = np.eye(4)
            T[:3, :] = np.array(v).reshape(3, 4)
            out.append(T)
    return out


def inv(T):
    Ti = np.eye(4)
    Ti[:3, :3] = T[:3, :3].T
    Ti[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return Ti


def rot_angle_deg(R):
    c = (np.trace(R) - 1) / 2
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def per_pair_errors(rundir, cluster, gt_obj):
    est = read_kitti(os.path.join(rundir, "objects", f"{cluster}.txt"))
    fpath = os.path.join(rundir, "objects", f"{cluster}_frames.txt")
    if os.path.exists(fpath):
        frames = [int(x) for x in open(fpath).read().split()]
    else:
        frames = list(range(len(est)))
    assert len(frames) == len(est), (rundir, cluster)
    X = dict(zip(frames, est))
    cam_e = read_kitti(os.path.join(rundir, "camera_trajectory.txt"))
    cam_g = read_kitti(os.path.join(rundir, "camera_trajectory_gt.txt"))
    Xg = read_kitti(os.path.join(rundir, "objects_gt", f"{gt_obj}.txt"))
    out = {}
    for k in frames:
        if k - 1 not in X:
            continue
        Ce, Cg = cam_e[k - 1], cam_g[k - 1]
        He = inv(Ce) @ X[k] @ inv(X[k - 1]) @ Ce
        Hg = inv(Cg) @ Xg[k] @ inv(Xg[k - 1]) @ Cg
        c = (inv(Cg) @ Xg[k - 1])[:, 3]
        me_r = rot_angle_deg(Hg[:3, :3].T @ He[:3, :3])
        me_t = float(np.linalg.norm((He @ c)[:3] - (Hg @ c)[:3]))
        out[k] = (me_r, me_t)
    return out


def frame_positions(seqdir):
    cam = {}
    for line in open(os.path.join(seqdir, "camera.txt")):
        if line.strip() and not line.startswith("#"):
            k, v = line.split()
            cam[k] = float(v)
    lm_obj = {}
    with open(os.path.join(seqdir, "gt_landmarks.csv")) as f:
        for r in csv.DictReader(f):
            lm_obj[int(r["landmark"])] = int(r["object"])
    xs = defaultdict(list)
    with open(os.path.join(seqdir, "observations.csv")) as f:
        rd = csv.reader(f)
        next(rd)
        for r in rd:
            o = lm_obj[int(r[1])]
            if o:
                xs[(o, int(r[0]))].append(abs((float(r[2]) - cam["cx"]) / cam["fx"]))
    return {k: float(np.median(v)) for k, v in xs.items()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--root", default="/tmp/r37")
    ap.add_argument("--seeds", default="1,3,4,5,6,7,8,9,10")
    args = ap.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    inputs = ["rect", "noise1", "noise2", "radtan", "equidistant"]
    errs = {}  # (seed, inp) -> {gt_obj: {frame: (me_r, me_t)}}
    check = []
    for s in seeds:
        for inp in inputs:
            rd = os.path.join(args.root, "R", f"s{s}_{inp}")
            m = json.load(open(os.path.join(rd, "metrics.json")))
            d = {}
            for o in m["objects"]["per_object"]:
                if not o.get("found"):
                    continue
                e = per_pair_errors(rd, o["cluster"], o["gt_object"])
                d[o["gt_object"]] = e
                if e:
                    check.append((len(e), o["me_pairs"], np.mean([v[0] for v in e.values()]), o["me_r_deg"],
                                  np.mean([v[1] for v in e.values()]), o["me_t_m"]))
            errs[(s, inp)] = d
    ch = np.array(check)
    print("### Check of the per-frame recomputation against metrics.json\n")
    print(f"- objects: {len(ch)}; pair count equal: {int((ch[:,0]==ch[:,1]).sum())}; "
          f"max |mean ME_r - me_r_deg| = {np.max(np.abs(ch[:,2]-ch[:,3])):.2e} deg; "
          f"max |mean ME_t - me_t_m| = {np.max(np.abs(ch[:,4]-ch[:,5])):.2e} m; "
          f"relative ME_t: max {np.max(np.abs(ch[:,4]-ch[:,5])/ch[:,5]):.2e}\n")

    pos = {s: frame_positions(os.path.join(args.root, f"s{s}")) for s in seeds}
    edges = [0, 0.1, 0.2, 0.35, 0.5, 2.0]
    print("### Per frame pair, paired with the rectified run (same seed, object, frame), by the object's "
          "position in that frame (median |u-cx|/fx of its true landmarks' keypoints)\n")
    print("Cells: n pairs; ME_r ratio = median over pairs of (input / rect) per-pair ME_r, and the ratio of "
          "the bin's mean ME_r (input mean / rect mean); same for ME_t.\n")
    print("| input | x bin | n pairs (objects) | rect mean ME_r (deg) | ME_r: median pair ratio, ratio of means | rect mean ME_t (m) | ME_t: median pair ratio, ratio of means |")
    print("|---|---|---|---|---|---|---|")
    summary = {}
    for inp in ["equidistant", "radtan", "noise1", "noise2"]:
        rows = []
        for s in seeds:
            a, b = errs[(s, "rect")], errs[(s, inp)]
            for g in set(a) & set(b):
                for k in set(a[g]) & set(b[g]):
                    x = pos[s].get((g, k))
                    if x is None:
                        continue
                    rows.append((s, g, k, x, a[g][k][0], b[g][k][0], a[g][k][1], b[g][k][1]))
        R = np.array([r[3:] for r in rows])
        objs = np.array([r[0] * 100 + r[1] for r in rows])
        summary[inp] = (R, objs)
        for i in range(len(edges) - 1):
            m = (R[:, 0] >= edges[i]) & (R[:, 0] < edges[i + 1])
            if m.sum() == 0:
                continue
            rr = R[m]
            lab = f"{edges[i]:.2f}–{edges[i+1]:.2f}" if edges[i + 1] < 2 else f">= {edges[i]:.2f}"
            print(f"| {inp} | {lab} | {m.sum()} ({len(set(objs[m]))}) | {rr[:,1].mean():.3f} | "
                  f"{np.median(rr[:,2]/np.maximum(rr[:,1],1e-9)):.2f}, {rr[:,2].mean()/rr[:,1].mean():.2f} | "
                  f"{rr[:,3].mean():.4f} | {np.median(rr[:,4]/np.maximum(rr[:,3],1e-9)):.2f}, {rr[:,4].mean()/rr[:,3].mean():.2f} |")
    print()

    # Within-object test: the slope of log(input/rect) per pair on x, objects as clusters;
    # permutation by shuffling x within each object (keeps each object's level).
    print("### Within-object trend: Spearman rho of x against log(ME_input / ME_rect) per pair, x centred "
          "within each object; p from shuffling x within objects (5000 shuffles)\n")
    print("| input | pairs (objects that span >= 0.1 in x) | ME_r rho, p | ME_t rho, p |")
    print("|---|---|---|---|")
    rng = np.random.default_rng(3)

    def rank_corr(a, b):
        ra = np.argsort(np.argsort(a)).astype(float); rb = np.argsort(np.argsort(b)).astype(float)
        ra -= ra.mean(); rb -= rb.mean()
        return float((ra * rb).sum() / math.sqrt((ra * ra).sum() * (rb * rb).sum()))

    for inp in ["equidistant", "radtan", "noise1", "noise2"]:
        R, objs = summary[inp]
        keep = np.zeros(len(R), bool)
        for o in set(objs):
            m = objs == o
            if R[m, 0].max() - R[m, 0].min() >= 0.1:
                keep |= m
        Rk, ok = R[keep], objs[keep]
        xc = Rk[:, 0].copy()
        for o in set(ok):
            m = ok == o
            xc[m] -= Rk[m, 0].mean()
        cells = []
        for col_e, col_r in [(2, 1), (4, 3)]:
            lr = np.log(np.maximum(Rk[:, col_e], 1e-6) / np.maximum(Rk[:, col_r], 1e-6))
            r0 = rank_corr(xc, lr)
            cnt = 0
            for _ in range(5000):
                xs = xc.copy()
                for o in set(ok):
                    m = np.where(ok == o)[0]
                    xs[m] = xs[rng.permutation(m)]
                if abs(rank_corr(xs, lr)) >= abs(r0) - 1e-12:
                    cnt += 1
            cells.append(f"{r0:+.2f}, {(cnt+1)/5001:.2f}")
        print(f"| {inp} | {keep.sum()} ({len(set(ok))}) | {cells[0]} | {cells[1]} |")
    print()
    family_trend(errs, pos, seeds)


def family_trend(errs, pos, seeds, nperm=5000):
    """Within-object trend against a reference averaged over runs (geometric mean of the reference
    runs' per-pair errors); p from circular shifts of x along each object's pair sequence (keeps
    the autocorrelation of x and of the errors along the track)."""
    rng = np.random.default_rng(11)
    combos = [("equidistant", ["rect", "noise1", "noise2"]), ("radtan", ["rect", "noise1", "noise2"]),
              ("equidistant", ["noise1", "noise2"]), ("radtan", ["noise1", "noise2"]),
              ("rect", ["noise1", "noise2"]), ("noise1", ["rect", "noise2"]), ("noise2", ["rect", "noise1"])]
    print("### Within-object trend against the family (reference = geometric mean of the listed runs' per-pair errors); "
          "x centred within each object, objects spanning >= 0.1 in x; p from circular shifts of x within objects\n")
    print("| input | reference | pairs (objects) | ME_r: rho, p, far/near (x above/below the object's mean) geo. mean ratio | ME_t: rho, p, far/near |")
    print("|---|---|---|---|---|")

    def rank_corr(a, b):
        ra = np.argsort(np.argsort(a)).astype(float); rb = np.argsort(np.argsort(b)).astype(float)
        ra -= ra.mean(); rb -= rb.mean()
        return float((ra * rb).sum() / math.sqrt((ra * ra).sum() * (rb * rb).sum()))

    for inp, ref in combos:
        groups = []  # per object: arrays x, lr_r, lr_t (ordered by frame)
        for s in seeds:
            runs = [errs[(s, i)] for i in [inp] + ref]
            common = set.intersection(*[set(r) for r in runs])
            for g in common:
                frames = sorted(set.intersection(*[set(r[g]) for r in runs]))
                frames = [k for k in frames if (g, k) in pos[s]]
                if len(frames) < 3:
                    continue
                x = np.array([pos[s][(g, k)] for k in frames])
                if x.max() - x.min() < 0.1:
                    continue
                e = np.array([[runs[0][g][k][j] for k in frames] for j in (0, 1)])
                rf = np.array([[np.exp(np.mean([np.log(max(r[g][k][j], 1e-6)) for r in runs[1:]])) for k in frames] for j in (0, 1)])
                lr = np.log(np.maximum(e, 1e-6) / rf)
                groups.append((x - x.mean(), lr))
        xc = np.concatenate([g[0] for g in groups])
        cells = []
        for j in (0, 1):
            lr = np.concatenate([g[1][j] for g in groups])
            r0 = rank_corr(xc, lr)
            cnt = 0
            for _ in range(nperm):
                xs = np.concatenate([np.roll(g[0], rng.integers(len(g[0]))) for g in groups])
                if abs(rank_corr(xs, lr)) >= abs(r0) - 1e-12:
                    cnt += 1
            fn = np.exp(lr[xc > 0].mean() - lr[xc <= 0].mean())
            cells.append(f"{r0:+.2f}, {(cnt + 1) / (nperm + 1):.2f}, {fn:.2f}")
        print(f"| {inp} | {'+'.join(ref)} | {len(xc)} ({len(groups)}) | {cells[0]} | {cells[1]} |")
    print()


if __name__ == "__main__":
    main()
