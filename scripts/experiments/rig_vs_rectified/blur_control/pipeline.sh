#!/bin/bash
# waits for the synths, makes blurred copies, runs all sequences one at a time
cd /tmp/blur
while ! grep -q DONE logs/synth_rc.txt; do sleep 5; done
SIGA=0.6; SIGB=0.5
for n in 1 3 4 5 6 7 8 9 10; do
  for tag in A B; do
    [ $tag = A ] && sig=$SIGA || sig=$SIGB
    d=/tmp/blur/s${n}_blur$tag
    rm -rf $d && cp -a /tmp/blur/s$n $d
    nice -n 10 ./blur apply $sig $d/sequences/00/image_0/*.png $d/sequences/00/image_1/*.png; echo "blur s${n}_blur$tag sigma=$sig rc=$?" >> logs/blur_rc.txt
  done
done
echo BLURDONE >> logs/blur_rc.txt
for n in 1 3 4 5 6 7 8 9 10; do
  for name in s$n s${n}_noise1 s${n}_noise2 s${n}_blurA s${n}_blurB; do
    t0=$(date +%s.%N)
    nice -n 10 /tmp/blur/cslam run /tmp/blur/$name --out /tmp/blur/R/$name --sequential --no-progress --pictures 0 --overwrite > logs/run_$name.log 2>&1
    rc=$?; t1=$(date +%s.%N)
    echo "$name rc=$rc t=$(echo "$t1 - $t0" | bc)" >> logs/run_rc.txt
  done
done
echo DONE >> logs/run_rc.txt
