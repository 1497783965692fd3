#!/usr/bin/env bash
# A real single-node Slurm (scripts/slurm-local.sh) runs a 3-entry manifest (KITTI odometry
# clip_a, KITTI raw drive 0009, one synthetic sequence) through `--executor slurm`; the table
# must equal the local executor's figure for figure, timings, frames/s and memory aside.
# Exit 77 (skipped) where Slurm is not installed or we are not root.
set -euo pipefail
CSLAM=$1; ROOT=$2; DATA=$3
command -v slurmctld >/dev/null && command -v munged >/dev/null && [ "$(id -u)" -eq 0 ] || { echo "skipped: needs root and slurm-wlm + munge (scripts/install_deps.sh)"; exit 77; }
TMP=$(mktemp -d /tmp/cslam_slurm_suite_XXXXXX)
SLURM_DIR="$TMP/slurm"
trap 'bash "$ROOT/scripts/slurm-local.sh" down "$SLURM_DIR"; rm -rf "$TMP"' EXIT
eval "$(bash "$ROOT/scripts/slurm-local.sh" up "$SLURM_DIR")"
cat > "$TMP/m.yaml" <<YAML
slurm: {time: "00:10:00", mem: 1G, cpus_per_task: 1}
entries:
  - name: clip_a
    input: $DATA/kitti_odometry/sequences/clip_a
    max_frames: 30
  - name: raw_0009
    input: $DATA/kitti_raw/2011_09_26/2011_09_26_drive_0009_sync
    max_frames: 30
  - synthetic: {preset: outdoor, seed: 2, frames: 40}
YAML
"$CSLAM" bench --suite "$TMP/m.yaml" --out "$TMP/slurm_out" --executor slurm --slurm-poll 1 --no-progress
"$CSLAM" bench --suite "$TMP/m.yaml" --out "$TMP/local_out" --jobs 2 --no-progress
python3 - "$TMP/slurm_out/bench.json" "$TMP/local_out/bench.json" <<'PY'
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert a["executor"] == "slurm" and b["executor"] == "local", (a["executor"], b["executor"])
assert len(a["rows"]) == len(b["rows"]) == 3
timing = {"frames_per_s", "peak_rss_mb", "time_s"}
for ra, rb in zip(a["rows"], b["rows"]):
    assert ra["id"] == rb["id"] and ra["status"] == rb["status"] == "ok", (ra["id"], ra["status"], rb["status"], ra["error"])
    for k, v in ra["values"].items():
        if k not in timing:
            assert v == rb["values"][k], (ra["id"], k, v, rb["values"][k])
    ma, mb = ra["metrics"], rb["metrics"]
    for section in ("camera", "objects", "clustering", "landmarks"):
        assert ma[section] == mb[section], (ra["id"], section)
print("slurm table equals the local table figure for figure:", [r["id"] for r in a["rows"]])
PY
