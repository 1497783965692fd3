#!/bin/bash
for n in 1 3 4 5 6 7 8 9 10; do
  nice -n 10 /tmp/blur/cslam synth --preset outdoor --seed $n --frames 60 --out /tmp/blur/s$n --images --baseline 0.12 --supersample 3 > logs/synth_s$n.log 2>&1; echo "s$n rc=$?" >> logs/synth_rc.txt
  for g in 1 2; do
    nice -n 10 /tmp/blur/cslam synth --preset outdoor --seed $n --frames 60 --out /tmp/blur/s${n}_noise$g --images --baseline 0.12 --supersample 3 --grey-noise 1 --grey-noise-seed $g > logs/synth_s${n}_noise$g.log 2>&1; echo "s${n}_noise$g rc=$?" >> logs/synth_rc.txt
  done
done
echo DONE >> logs/synth_rc.txt
