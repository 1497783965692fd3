#!/usr/bin/env python3
"""Builds a long KITTI raw drive from a short one played forward and back (issue 24, item 7).

The new drive has the official layout (`cslam run` reads it as KITTI raw): its images and
oxts packets are symlinks to the source's, in the order 0, 1, ..., n-1, n-2, ..., 1, 0, 1, ...;
timestamps are 10 Hz from the source's first one; the date folder's calibration files are
symlinks too. When the new drive plays the source one way only (no turn) and the source has
tracklet labels, they are written for the new frame order (a stretch or a reversed drive keeps
its ground truth); a drive that turns gets none (a played-back object would be two objects).

Usage: scripts/make_long_drive.py [--start K] [--backward] FRAMES OUT_ROOT [SOURCE_DRIVE]
  SOURCE_DRIVE defaults to ../shared/data/kitti_raw/2011_09_26/2011_09_26_drive_0005_sync
  (relative to the project root); the drive is written to
  OUT_ROOT/<date>/<date>_drive_9<source drive number>_sync and its path printed.
  --start K   begin at source frame K (default 0; with --backward, the source's last frame)
  --backward  play backward first. Hard cases from the shared drives: the drive reversed
              (`--backward FRAMES_OF_SOURCE`), a stretch of it (`--start 60 40`).
"""
import datetime
import os
import sys
import xml.etree.ElementTree as ET


def ping_pong(n_source, frames, start=0, step=1):
    order, k = [], start
    for _ in range(frames):
        order.append(k)
        if n_source == 1:
            continue
        if not 0 <= k + step < n_source:
            step = -step
        k += step
    return order


def write_tracklets(source_xml, order, out_xml):
    """Tracklet labels of `source_xml` for the frames `order` (one-way: no frame repeats)."""
    new_index = {k: i for i, k in enumerate(order)}
    tree = ET.parse(source_xml)
    tracklets = tree.getroot().find("tracklets")
    kept = []
    for obj in tracklets.findall("item"):
        first = int(obj.find("first_frame").text)
        poses = obj.find("poses")
        items = poses.findall("item")
        frames = [(new_index[first + j], item) for j, item in enumerate(items)
                  if first + j in new_index]
        if not frames:
            continue
        frames.sort(key=lambda f: f[0])
        for item in items:
            poses.remove(item)
        for _, item in frames:
            poses.append(item)
        poses.find("count").text = str(len(frames))
        obj.find("first_frame").text = str(frames[0][0])
        kept.append(obj)
    for obj in tracklets.findall("item"):
        tracklets.remove(obj)
    for obj in kept:
        tracklets.append(obj)
    tracklets.find("count").text = str(len(kept))
    tree.write(out_xml, encoding="UTF-8", xml_declaration=True)


def main():
    args, start_frame, backward = sys.argv[1:], None, False
    while args and args[0].startswith("--"):
        flag = args.pop(0)
        if flag == "--backward":
            backward = True
        elif flag == "--start" and args:
            try:
                start_frame = int(args.pop(0))
            except ValueError:
                sys.exit("--start: expected a frame number")
        else:
            sys.exit(f"{flag}: unknown option\n" + __doc__)
    if len(args) not in (2, 3):
        sys.exit(__doc__)
    frames = int(args[0])
    if frames < 1:
        sys.exit("FRAMES must be >= 1")
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    source = os.path.abspath(args[2] if len(args) == 3 else os.path.join(
        root, "..", "shared", "data", "kitti_raw", "2011_09_26", "2011_09_26_drive_0005_sync"))
    date_dir = os.path.dirname(source)
    date = os.path.basename(date_dir)
    name = os.path.basename(source)  # <date>_drive_NNNN_sync
    number = name.split("_drive_")[1].split("_")[0]
    out_date = os.path.join(os.path.abspath(args[1]), date)
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
    if start_frame is None:
        start_frame = len(images) - 1 if backward else 0
    if not 0 <= start_frame < len(images):
        sys.exit(f"--start {start_frame}: the source has frames 0..{len(images) - 1}")
    order = ping_pong(len(images), frames, start_frame, -1 if backward else 1)
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
    labels = os.path.join(source, "tracklet_labels.xml")
    if os.path.exists(labels) and len(set(order)) == len(order):
        write_tracklets(labels, order, os.path.join(drive, "tracklet_labels.xml"))
    fmt = os.path.join(drive, "oxts", "dataformat.txt")
    if not os.path.lexists(fmt):
        os.symlink(os.path.join(source, "oxts", "dataformat.txt"), fmt)
    print(drive)


if __name__ == "__main__":
    main()
