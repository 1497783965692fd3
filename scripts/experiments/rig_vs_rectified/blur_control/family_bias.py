"""What analyze.py (the blur control) and rig_analyze.py (the rigs) share: each input's runs per
seed, their per-seed and pooled tables, and biases against the rectified family (rect and its two
±1-grey-level copies) with a bootstrap that resamples seeds."""
import json, math
import numpy as np

FAMILY = ["rect", "noise1", "noise2"]
METRICS = ["ate_m", "me_r_deg", "me_t_m"]


def med(v):
    return float(np.median(v)) if len(v) else float("nan")


def refs_of(inp):
    """The reference of an input: the whole family, or for a family member the other two."""
    return FAMILY if inp not in FAMILY else [f for f in FAMILY if f != inp]


class Runs:
    """paths: input -> run folder pattern with {n}. Bootstrap draws come from one generator in
    call order, so a script reproduces its numbers only when it asks in the same order."""

    def __init__(self, paths, seeds, nboot=2000, rng_seed=12345):
        self.seeds, self.nboot = list(seeds), nboot
        self.rng = np.random.default_rng(rng_seed)
        self.data = {inp: {n: self._load(p.format(n=n)) for n in self.seeds} for inp, p in paths.items()}

    @staticmethod
    def _load(folder):
        d = json.load(open(folder + "/metrics.json"))
        objs = {o["gt_object"]: o for o in d["objects"]["per_object"] if o["found"]}
        return d["camera"]["ate_m"], objs, len(d["objects"]["per_object"])

    def per_seed_table(self, inputs):
        out = ["## Per-seed results\n",
               "| seed | input | camera ATE m | objects found / gt | median obj ATE m | median ME_r deg | median ME_t m |",
               "|---|---|---|---|---|---|---|"]
        for n in self.seeds:
            for inp in inputs:
                cam, objs, ngt = self.data[inp][n]
                vals = {k: [o[k] for o in objs.values() if o[k] is not None] for k in METRICS}
                out.append(f"| {n} | {inp} | {cam:.4f} | {len(objs)} / {ngt} | {med(vals['ate_m']):.4f} | "
                           f"{med(vals['me_r_deg']):.3f} | {med(vals['me_t_m']):.4f} |")
        return out

    def pooled_table(self, inputs):
        out = ["\n## Pooled over seeds (medians over found objects; camera ATE: median over seeds)\n",
               "| input | objects found | median obj ATE m | median ME_r deg | median ME_t m | median camera ATE m |",
               "|---|---|---|---|---|---|"]
        for inp in inputs:
            allobjs = [o for n in self.seeds for o in self.data[inp][n][1].values()]
            vals = {k: [o[k] for o in allobjs if o[k] is not None] for k in METRICS}
            cams = [self.data[inp][n][0] for n in self.seeds]
            out.append(f"| {inp} | {len(allobjs)} | {med(vals['ate_m']):.4f} | {med(vals['me_r_deg']):.3f} | "
                       f"{med(vals['me_t_m']):.4f} | {med(cams):.4f} |")
        return out

    def ratios_for(self, inp, refs, key):
        """Per seed: log(input / geometric mean of refs) over objects found by input and all refs."""
        per_seed = {}
        for n in self.seeds:
            lr = []
            for g, o in self.data[inp][n][1].items():
                if not all(g in self.data[r][n][1] for r in refs):
                    continue
                x = o[key]
                ys = [self.data[r][n][1][g][key] for r in refs]
                if x is None or any(y is None for y in ys) or x <= 0 or any(y <= 0 for y in ys):
                    continue
                lr.append(math.log(x) - np.mean(np.log(ys)))
            per_seed[n] = lr
        return per_seed

    def cam_ratios(self, inp, refs):
        return {n: [math.log(self.data[inp][n][0]) - np.mean([math.log(self.data[r][n][0]) for r in refs])]
                for n in self.seeds}

    def boot(self, per_seed):
        """Geometric-mean ratio, its 95 % interval over seed resamples, and the count."""
        allv = [v for n in self.seeds for v in per_seed[n]]
        if not allv:
            return float("nan"), float("nan"), float("nan"), 0
        est = math.exp(np.mean(allv))
        bs = []
        for _ in range(self.nboot):
            pick = self.rng.choice(self.seeds, size=len(self.seeds), replace=True)
            v = [x for s in pick for x in per_seed[s]]
            if v:
                bs.append(math.exp(np.mean(v)))
        lo, hi = np.percentile(bs, [2.5, 97.5])
        return est, lo, hi, len(allv)

    def bias_row(self, inp, refs):
        """One row of the bias table: objects paired, then object ATE, ME_r, ME_t and camera ATE."""
        cells, nobj = [], None
        for key in METRICS:
            est, lo, hi, cnt = self.boot(self.ratios_for(inp, refs, key))
            if key == "ate_m":
                nobj = cnt
            cells.append(f"{est:.2f} [{lo:.2f}, {hi:.2f}]")
        est, lo, hi, _ = self.boot(self.cam_ratios(inp, refs))
        cells.append(f"{est:.2f} [{lo:.2f}, {hi:.2f}]")
        return f"| {inp} | {'/'.join(refs)} | {nobj} | " + " | ".join(cells) + " |"

    def cam_ratio(self, inp, n):
        return math.exp(self.cam_ratios(inp, refs_of(inp))[n][0])

    def found_by_all(self, members, n):
        return set.intersection(*[set(self.data[f][n][1]) for f in members])


HEADER = ["| input | reference | n obj | obj ATE bias [95 % CI] | ME_r bias [95 % CI] | ME_t bias [95 % CI] | camera ATE bias [95 % CI] |",
          "|---|---|---|---|---|---|---|"]
