#!/usr/bin/python3
"""Image-level check of the periphery hypothesis: rectify each rig's raw left image back to the
rendered camera (opencv_rectified.yml: M1, D1, R1, P1; bilinear, as cslam's remap) with numpy,
and compare with the directly rendered rectified left image, binned by |u - cx| / fx.

Reports per bin: mean |difference| (grey levels) and the ratio of gradient energy
(rectified-back / rendered), a sharpness measure (< 1: the rectified-back image is blurrier).
No OpenCV/PIL here: a minimal PNG decoder (8-bit grey, non-interlaced) with zlib + numpy.

Usage: /usr/bin/python3 image_periphery.py [--seeds 1,2,3] [--frames 0,30,59]
"""
import argparse
import os
import re
import struct
import zlib

import numpy as np


def read_png_grey8(path):
    b = open(path, "rb").read()
    assert b[:8] == b"\x89PNG\r\n\x1a\n"
    pos = 8
    idat = []
    w = h = None
    while pos < len(b):
        n, typ = struct.unpack(">I4s", b[pos:pos + 8])
        data = b[pos + 8:pos + 8 + n]
        if typ == b"IHDR":
            w, h, depth, ctype, _, _, inter = struct.unpack(">IIBBBBB", data)
            assert depth == 8 and ctype == 0 and inter == 0, (depth, ctype, inter)
        elif typ == b"IDAT":
            idat.append(data)
        elif typ == b"IEND":
            break
        pos += 12 + n
    raw = np.frombuffer(zlib.decompress(b"".join(idat)), np.uint8).reshape(h, w + 1)
    out = np.zeros((h, w), np.uint8)
    prev = np.zeros(w, np.int32)
    for y in range(h):
        f = raw[y, 0]
        line = raw[y, 1:].astype(np.int32)
        if f == 0:
            cur = line
        elif f == 1:
            cur = np.cumsum(line) & 255
        elif f == 2:
            cur = (line + prev) & 255
        else:
            cur = np.zeros(w, np.int32)
            left = 0
            for x in range(w):
                up = prev[x]
                if f == 3:
                    v = (line[x] + ((left + up) >> 1)) & 255
                else:  # Paeth
                    ul = prev[x - 1] if x > 0 else 0
                    p = left + up - ul
                    pa, pb, pc = abs(p - left), abs(p - up), abs(p - ul)
                    pr = left if (pa <= pb and pa <= pc) else (up if pb <= pc else ul)
                    v = (line[x] + pr) & 255
                cur[x] = v
                left = v
        out[y] = cur
        prev = cur
    return out


def read_yml_matrices(path):
    txt = open(path).read()
    mats = {}
    for m in re.finditer(r"(\w+): !!opencv-matrix\s+rows: (\d+)\s+cols: (\d+)\s+dt: \w\s+data: \[([^\]]*)\]", txt):
        r, c = int(m.group(2)), int(m.group(3))
        mats[m.group(1)] = np.array([float(x) for x in m.group(4).replace("\n", " ").split(",")]).reshape(r, c)
    model = re.search(r"distortion_model: (\w+)", txt)
    return mats, (model.group(1) if model else "radtan")


def rectify_map(mats, model, w, h):
    K, D, R, P = mats["M1"], mats["D1"].ravel(), mats["R1"], mats["P1"]
    Kp = P[:, :3]
    u, v = np.meshgrid(np.arange(w, dtype=float), np.arange(h, dtype=float))
    pts = np.stack([u.ravel(), v.ravel(), np.ones(u.size)])
    rays = np.linalg.inv(Kp @ R) @ pts
    a, b = rays[0] / rays[2], rays[1] / rays[2]
    if model == "fisheye":
        r = np.hypot(a, b)
        th = np.arctan(r)
        k1, k2, k3, k4 = D[:4]
        thd = th * (1 + k1 * th**2 + k2 * th**4 + k3 * th**6 + k4 * th**8)
        s = np.where(r > 1e-12, thd / np.maximum(r, 1e-12), 1.0)
        xd, yd = a * s, b * s
    else:
        k1, k2, p1, p2 = D[:4]
        k3 = D[4] if len(D) > 4 else 0.0
        r2 = a * a + b * b
        rad = 1 + k1 * r2 + k2 * r2**2 + k3 * r2**3
        xd = a * rad + 2 * p1 * a * b + p2 * (r2 + 2 * a * a)
        yd = b * rad + p1 * (r2 + 2 * b * b) + 2 * p2 * a * b
    mx = K[0, 0] * xd + K[0, 2]
    my = K[1, 1] * yd + K[1, 2]
    return mx.reshape(h, w), my.reshape(h, w)


def bilinear(img, mx, my):
    h, w = img.shape
    x0 = np.floor(mx).astype(int)
    y0 = np.floor(my).astype(int)
    fx, fy = mx - x0, my - y0
    valid = (x0 >= 0) & (y0 >= 0) & (x0 + 1 < w) & (y0 + 1 < h)
    x0c, y0c = np.clip(x0, 0, w - 2), np.clip(y0, 0, h - 2)
    I = img.astype(float)
    out = (I[y0c, x0c] * (1 - fx) * (1 - fy) + I[y0c, x0c + 1] * fx * (1 - fy)
           + I[y0c + 1, x0c] * (1 - fx) * fy + I[y0c + 1, x0c + 1] * fx * fy)
    return out, valid


def grad_energy(img):
    gx = np.zeros_like(img)
    gy = np.zeros_like(img)
    gx[:, 1:-1] = (img[:, 2:] - img[:, :-2]) / 2
    gy[1:-1, :] = (img[2:, :] - img[:-2, :]) / 2
    return gx * gx + gy * gy


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--root", default="/tmp/r37")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--frames", default="0,30,59")
    args = ap.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    frames = [int(f) for f in args.frames.split(",")]
    edges = np.array([0, 0.2, 0.4, 0.6, 0.8, 1.01])
    res = {}
    for lens in ["radtan", "equidistant"]:
        acc_d = np.zeros(len(edges) - 1)
        acc_ge = np.zeros(len(edges) - 1)
        acc_gr = np.zeros(len(edges) - 1)
        acc_n = np.zeros(len(edges) - 1)
        for s in seeds:
            rig = os.path.join(args.root, f"s{s}", f"rig_{lens}")
            mats, model = read_yml_matrices(os.path.join(rig, "opencv_rectified.yml"))
            P = mats["P1"]
            ref0 = read_png_grey8(os.path.join(args.root, f"s{s}", "sequences/00/image_0/000000.png"))
            h, w = ref0.shape
            mx, my = rectify_map(mats, model, w, h)
            xn = np.abs((np.arange(w) - P[0, 2]) / P[0, 0])
            xn = np.broadcast_to(xn, (h, w))
            names = sorted(os.listdir(os.path.join(rig, "mav0/cam0/data")), key=lambda n: int(n[:-4]))
            for f in frames:
                ref = read_png_grey8(os.path.join(args.root, f"s{s}", f"sequences/00/image_0/{f:06d}.png")).astype(float)
                raw = read_png_grey8(os.path.join(rig, "mav0/cam0/data", names[f]))
                rect, valid = bilinear(raw, mx, my)
                d = np.abs(rect - ref)
                ge_rect, ge_ref = grad_energy(rect), grad_energy(ref)
                inner = np.zeros_like(valid)
                inner[2:-2, 2:-2] = True
                for i in range(len(edges) - 1):
                    m = valid & inner & (xn >= edges[i]) & (xn < edges[i + 1])
                    acc_d[i] += d[m].sum()
                    acc_ge[i] += ge_rect[m].sum()
                    acc_gr[i] += ge_ref[m].sum()
                    acc_n[i] += m.sum()
        res[lens] = (acc_d / acc_n, acc_ge / acc_gr, acc_n)
    print(f"seeds {seeds}, frames {frames}, left images\n")
    print("| \\|u-cx\\|/fx bin | pinhole/equidistant radial sampling cos^2(theta) at bin centre | radtan: mean \\|diff\\| | radtan: gradient energy ratio | equidistant: mean \\|diff\\| | equidistant: gradient energy ratio |")
    print("|---|---|---|---|---|---|")
    for i in range(len(edges) - 1):
        c = (edges[i] + min(edges[i + 1], 1.0)) / 2
        print(f"| {edges[i]:.1f}–{min(edges[i+1],1.0):.1f} | {1/(1+c*c):.2f} | {res['radtan'][0][i]:.2f} | {res['radtan'][1][i]:.3f} | "
              f"{res['equidistant'][0][i]:.2f} | {res['equidistant'][1][i]:.3f} |")


if __name__ == "__main__":
    main()
