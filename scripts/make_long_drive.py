#!/usr/bin/env python3
"""Builds a long KITTI raw drive from a short one played forward and back (issue 24, item 7).

The new drive has the official layout (`cslam run` reads it as KITTI raw): its images and
oxts packets are symlinks to the source's, in the order 0, 1, ..., n-1, n-2, ..., 1, 0, 1, ...;
timestamps are 10 Hz from the source's first one; the date folder's calibration files are
symlinks too. No tracklet labels (the played-back objects would not match them).

Usage: scripts/make_long_drive.py FRAMES OUT_ROOT [SOURCE_DRIVE]
  SOURCE_DRIVE defaults to ../shared/data/kitti_raw/2011_09_26/2011_09_26_drive_0005_sync
  (relative to the project root); the drive is written to
  OUT_ROOT/<date>/<date>_drive_9<source drive number>_sync and its path printed.
"""
import datetime
import os
import sys


def ping_pong(n_source, frames):
    order, k, step = [], 0, 1
    for _ in range(frames):
        order.append(k)
        if n_source == 1:
            continue
        if not 0 <= k + step < n_source:
            step = -step
        k += step
    return order


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    frames = int(sys.argv[1])
    if frames < 1:
        sys.exit("FRAMES must be >= 1")
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    source = os.path.abspath(sys.argv[3] if len(sys.argv) == 4 else os.path.join(
        root, "..", "shared", "data", "kitti_raw", "2011_09_26", "2011_09_26_drive_0005_sync"))
    date_dir = os.path.dirname(source)
    date = os.path.basename(date_dir)
    name = os.path.basename(source)  # <date>_drive_NNNN_sync
    number = name.split("_drive_")[1].split("_")[0]
    out_date = os.path.join(os.path.abspath(sys.argv[2]), date)
    drive = os.path.join(out_date, f"{date}_drive_9{number[1:]}_sync")
    images = sorted(f for f in os.listdir(os.path.join(source, "image_00", "data")) if f.endswith(".png"))
    if not images:
        sys.exit(f"{source}/image_00/data: no images")
    with open(os.path.join(source, "image_00", "timestamps.txt")) as f:
        first = f.readline().strip()
    start = datetime.datetime.strptime(first[:26], "%Y-%m-%d %H:%M:%S.%f")
    os.makedirs(out_date, exist_ok=True)
    for calib in ("calib_cam_to_cam.txt", "calib_imu_to_velo.txt", "calib_velo_to_cam.txt"):
        link = os.path.join(out_date, calib)
        if not os.path.lexists(link):
            os.symlink(os.path.join(date_dir, calib), link)
    order = ping_pong(len(images), frames)
    stamps = [(start + datetime.timedelta(seconds=0.1 * i)).strftime("%Y-%m-%d %H:%M:%S.%f") + "000"
              for i in range(frames)]
    for sub, ext in (("image_00", ".png"), ("image_01", ".png"), ("oxts", ".txt")):
        data = os.path.join(drive, sub, "data")
        os.makedirs(data, exist_ok=True)
        for i, k in enumerate(order):
            link = os.path.join(data, f"{i:010d}{ext}")
            if os.path.lexists(link):
                os.remove(link)
            os.symlink(os.path.join(source, sub, "data", f"{k:010d}{ext}"), link)
        with open(os.path.join(drive, sub, "timestamps.txt"), "w") as f:
            f.write("\n".join(stamps) + "\n")
    fmt = os.path.join(drive, "oxts", "dataformat.txt")
    if not os.path.lexists(fmt):
        os.symlink(os.path.join(source, "oxts", "dataformat.txt"), fmt)
    print(drive)


if __name__ == "__main__":
    main()
