#!/bin/bash
# Section 2 of docs/experiments/2026-12-06-generated-rig-vs-rectified.md, as re-run in
# docs/experiments/2026-12-07-generated-rig-vs-rectified-after-object-adjustment.md.
# Strictly sequential (one heavy command at a time). Usage: driver.sh SEED...
set -u
# CSLAM: the binary (default build/apps/cslam of this checkout); WORK: where sequences and runs go.
C=${CSLAM:-$(cd "$(dirname "$0")/../../.." && pwd)/build/apps/cslam}
WORK=${WORK:-/tmp/r37}
mkdir -p "$WORK" && cd "$WORK"
mkdir -p R logs
t() { local name=$1; shift; local s=$(date +%s); "$@" > logs/$name.log 2>&1; local rc=$?; echo "$(date +%T) $name rc=$rc $(( $(date +%s)-s ))s" >> logs/driver.log; }
for n in "$@"; do
  if [ ! -f s$n/rig_equidistant/mav0/cam1/data/6900000000.png ]; then
    t synth_s$n $C synth --preset outdoor --seed $n --frames 60 --out s$n --images --rig radtan --rig equidistant
  fi
  for g in 1 2; do
    if [ ! -f s${n}_noise$g/sequences/00/image_1/000059.png ]; then
      t synth_s${n}_noise$g $C synth --preset outdoor --seed $n --frames 60 --out s${n}_noise$g --images \
          --baseline 0.12 --supersample 3 --grey-noise 1 --grey-noise-seed $g
    fi
  done
  [ -f R/s${n}_rect/metrics.json ] || t run_s${n}_rect $C run s$n --out R/s${n}_rect --sequential --no-progress
  for g in 1 2; do
    [ -f R/s${n}_noise$g/metrics.json ] || t run_s${n}_noise$g $C run s${n}_noise$g --out R/s${n}_noise$g --sequential --no-progress
  done
  for l in radtan equidistant; do
    [ -f R/s${n}_$l/metrics.json ] || t run_s${n}_$l $C run s$n/rig_$l --calib s$n/rig_$l/opencv_rectified.yml --out R/s${n}_$l --sequential --no-progress
    [ -f R/s${n}_${l}_own/metrics.json ] || t run_s${n}_${l}_own $C run s$n/rig_$l --gt s$n/rig_$l/groundtruth_tum.txt --out R/s${n}_${l}_own --sequential --no-progress
  done
done
echo "$(date +%T) done $*" >> logs/driver.log
