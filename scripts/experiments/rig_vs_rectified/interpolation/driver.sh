#!/bin/bash
cd /tmp/r37c
for i in lanczos cubic; do for n in 1 3 4 5 6 7 8 9 10; do for l in radtan equidistant; do
  t0=$(date +%s)
  ./mkseq.sh $n $l $i > logs/mk_s${n}_${l}_${i}.log 2>&1 || { echo "mk fail $n $l $i"; continue; }
  /tmp/cslam_f5f06f5 run s${n}_${l}_${i} --out R/s${n}_${l}_${i} --sequential --no-progress > logs/run_s${n}_${l}_${i}.log 2>&1
  echo "$(date +%T) s${n}_${l}_${i} rc=$? $(( $(date +%s)-t0 ))s"
done; done; done
