#!/usr/bin/env python3
"""How far the OXTS ground truth of a KITTI raw drive agrees with itself.

Per segment of N frames, the path length of the OXTS positions (Mercator projection, as
system/datasets/oxts.cc and the KITTI devkit do) against the path integrated from the OXTS's own
horizontal velocity (vf, vl) over the timestamps. With exact positions the ratio is 1; the
spread of the ratio is the ground truth's own scale noise over such segments, which any
estimated trajectory compared with those positions inherits. Also prints the receiver's
position accuracy field (posacc, m).

usage: scripts/oxts_consistency.py DRIVE_DIR [N=20]
"""
import glob
import math
import os
import sys

EARTH_RADIUS = 6378137.0


def seconds(stamp):
    h, m, s = stamp.split()[1].split(":")
    return int(h) * 3600 + int(m) * 60 + float(s)


def main():
    drive = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 20
    files = sorted(glob.glob(os.path.join(drive, "oxts", "data", "*.txt")))
    packets = [list(map(float, open(f).read().split())) for f in files]
    times = [seconds(l) for l in open(os.path.join(drive, "oxts", "timestamps.txt")) if l.strip()]
    scale = math.cos(packets[0][0] * math.pi / 180)
    pos = [(scale * EARTH_RADIUS * p[1] * math.pi / 180,
            scale * EARTH_RADIUS * math.log(math.tan((90 + p[0]) * math.pi / 360)), p[2])
           for p in packets]
    speed = [math.hypot(p[8], p[9]) for p in packets]
    print("posacc (m): min %.3f max %.3f" % (min(p[23] for p in packets), max(p[23] for p in packets)))
    total_p = total_v = 0.0
    for k in range(0, len(packets) - 1, n):
        hi = min(k + n, len(packets) - 1)
        dp = sum(math.dist(pos[i], pos[i + 1]) for i in range(k, hi))
        dv = sum(0.5 * (speed[i] + speed[i + 1]) * (times[i + 1] - times[i]) for i in range(k, hi))
        total_p += dp
        total_v += dv
        print("frames %3d-%3d  positions %7.3f m  velocity %7.3f m  ratio %.4f" % (k, hi, dp, dv, dp / dv))
    print("whole drive  positions %.3f m  velocity %.3f m  ratio %.4f" % (total_p, total_v, total_p / total_v))


if __name__ == "__main__":
    main()
