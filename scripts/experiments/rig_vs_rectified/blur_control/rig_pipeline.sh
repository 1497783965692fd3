#!/bin/bash
# renders the rigs one seed at a time, runs both lenses of each seed right after; stops rendering after DEADLINE
cd /tmp/blur2
DEADLINE=$(date -d '2026-12-07 23:38:18' +%s)
for n in 1 3 4 5 6 7 8 9 10; do
  if [ $(date +%s) -ge $DEADLINE ]; then echo "deadline reached before s$n" >> logs/synth_rc.txt; break; fi
  t0=$(date +%s.%N)
  nice -n 15 /tmp/blur2/cslam synth --preset outdoor --seed $n --frames 60 --out /tmp/blur2/s$n --images --rig radtan --rig equidistant > logs/synth_s$n.log 2>&1
  rc=$?; t1=$(date +%s.%N)
  echo "s$n rc=$rc t=$(echo "$t1 - $t0" | bc)" >> logs/synth_rc.txt
  for l in radtan equidistant; do
    t0=$(date +%s.%N)
    nice -n 15 /tmp/blur2/cslam run /tmp/blur2/s$n/rig_$l --calib /tmp/blur2/s$n/rig_$l/opencv_rectified.yml --out /tmp/blur2/R/s${n}_$l --sequential --no-progress --pictures 0 --overwrite > logs/run_s${n}_$l.log 2>&1
    rc=$?; t1=$(date +%s.%N)
    echo "s${n}_$l rc=$rc t=$(echo "$t1 - $t0" | bc)" >> logs/run_rc.txt
  done
done
echo DONE >> logs/synth_rc.txt
