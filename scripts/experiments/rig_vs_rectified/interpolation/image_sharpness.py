#!/usr/bin/python3
"""Left images rectified back (this folder's s<n>_<lens>_<interp>) and a +-1 grey copy against the
rendered rectified image (/tmp/r37/s<n>/sequences/00/image_0): mean |diff| (grey levels) and
gradient-energy ratio (sum of squared central differences, rectified-back / rendered), whole image
(2 px border dropped) and centre |u-cx|/fx < 0.2."""
import sys
import numpy as np
sys.path.insert(0, "/tmp/r37")
from image_periphery import read_png_grey8, grad_energy

SEEDS = [1, 3, 4]
FRAMES = [0, 30, 59]
CX, FX = 639.5, 640.0
acc = {}
for s in SEEDS:
    for f in FRAMES:
        ref = read_png_grey8(f"/tmp/r37/s{s}/sequences/00/image_0/{f:06d}.png").astype(float)
        h, w = ref.shape
        inner = np.zeros((h, w), bool); inner[2:-2, 2:-2] = True
        centre = inner & (np.abs((np.arange(w) - CX) / FX) < 0.2)[None, :]
        gref = grad_energy(ref)
        srcs = {"noise1 copy": f"/tmp/r37/s{s}_noise1/sequences/00/image_0/{f:06d}.png"}
        for l in ["radtan", "equidistant"]:
            for i in ["linear", "cubic", "lanczos"]:
                srcs[f"{l} {i}"] = f"/tmp/r37c/s{s}_{l}_{i}/sequences/00/image_0/{f:06d}.png"
        for k, p in srcs.items():
            img = read_png_grey8(p).astype(float)
            d = np.abs(img - ref); g = grad_energy(img)
            a = acc.setdefault(k, np.zeros(6))
            a += [d[inner].sum(), inner.sum(), g[inner].sum(), gref[inner].sum(), d[centre].sum(), g[centre].sum() / gref[centre].sum()]
n = len(SEEDS) * len(FRAMES)
print(f"seeds {SEEDS}, frames {FRAMES}, left images, {n} images per row; centre-bin ratio averaged over images\n")
print("| image | mean \\|diff\\| (grey) | gradient energy ratio | centre: gradient energy ratio |")
print("|---|---|---|---|")
for k, a in acc.items():
    print(f"| {k} | {a[0]/a[1]:.2f} | {a[2]/a[3]:.3f} | {a[5]/n:.3f} |")
