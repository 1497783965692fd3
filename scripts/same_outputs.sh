#!/bin/bash
# Behaviour check for refactors: run a binary over KITTI raw 0005, the odometry clip and two
# generated synthetic sequences, online with --sequential (deterministic), renders off; then
# compare two such output folders file by file, timing excluded (metrics.json "timing",
# windows.csv, resources.csv, run.log).
#   scripts/same_outputs.sh run  BINARY OUT_DIR     # e.g. build/apps/cslam /tmp/after
#   scripts/same_outputs.sh diff DIR_A DIR_B        # exit 0 when identical
# Data: $CSLAM_SHARED_DATA, else ../shared/data beside the repository.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
data="${CSLAM_SHARED_DATA:-$here/../shared/data}"

compare() {
  local a="$1" b="$2" rc=0
  while IFS= read -r f; do
    case "$f" in
      *windows.csv|*resources.csv|*run.log|*console.log) continue ;;
      *metrics.json)
        if ! cmp -s <(python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); d.pop("timing",None); print(json.dumps(d,sort_keys=True))' "$a/$f") \
                    <(python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); d.pop("timing",None); print(json.dumps(d,sort_keys=True))' "$b/$f"); then
          echo "differs: $f"; rc=1
        fi ;;
      *) if ! cmp -s "$a/$f" "$b/$f"; then echo "differs: $f"; rc=1; fi ;;
    esac
  done < <(cd "$a" && find . -type f \( -name '*.csv' -o -name '*.txt' -o -name '*.tum' -o -name '*.json' \
                                        -o -name '*.ply' -o -name '*.pcd' -o -name '*.yaml' \) | sort)
  [ -z "$(diff <(cd "$a" && find . -type f | sort) <(cd "$b" && find . -type f | sort))" ] || {
    echo "the folders hold different files"; rc=1; }
  [ $rc -eq 0 ] && echo "identical (timing excluded)"
  return $rc
}

case "${1:-}" in
  diff) compare "$2" "$3" ;;
  run)
    bin="$(realpath "$2")"; out="$3"; mkdir -p "$out"
    flags=(--sequential --no-progress --snapshots-every 0 --overlays-every 0 --overwrite)
    for s in "outdoor 1" "indoor 2"; do
      set -- $s
      [ -d "$out/input_$1$2" ] || "$bin" synth --preset "$1" --seed "$2" --out "$out/input_$1$2" >/dev/null 2>&1
    done
    "$bin" run "$data/kitti_raw/2011_09_26/2011_09_26_drive_0005_sync" "${flags[@]}" --out "$out/raw_0005" >/dev/null 2>"$out/raw_0005.console.log"
    "$bin" run "$data/kitti_odometry/sequences/clip_a" "${flags[@]}" --out "$out/clip_a" >/dev/null 2>"$out/clip_a.console.log"
    "$bin" run "$out/input_outdoor1" "${flags[@]}" --out "$out/outdoor1" >/dev/null 2>"$out/outdoor1.console.log"
    "$bin" run "$out/input_indoor2" "${flags[@]}" --out "$out/indoor2" >/dev/null 2>"$out/indoor2.console.log"
    echo "outputs in $out" ;;
  *) sed -n 2,8p "$0"; exit 2 ;;
esac
