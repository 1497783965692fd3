#!/bin/bash
# mkseq.sh <seed> <lens radtan|equidistant> <interp linear|cubic|lanczos>
set -e
n=$1; l=$2; i=$3
src=/tmp/r37/s$n; dst=/tmp/r37c/s${n}_${l}_${i}
rm -rf "$dst"; mkdir -p "$dst/sequences/00"
for f in "$src"/*; do b=$(basename "$f"); case $b in rig_*|sequences) ;; *) cp -a "$f" "$dst/";; esac; done
for f in "$src"/sequences/00/*; do b=$(basename "$f"); case $b in image_0|image_1) ;; *) cp -a "$f" "$dst/sequences/00/";; esac; done
/tmp/r37c/rectify "$src/rig_$l" "$dst/sequences/00" "$i"
