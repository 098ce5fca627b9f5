#!/bin/bash
# On the GPU machine (device tool, carry [".gl", ".replay"]): two runtime folders A/B, each rank of a
# 2-rank split alone (relight --share R/2) and the one-process bake path (--share 0/1), alternated.
# Packed here (.replay/share.txz): the building and city bundles of bench/results/open-city-gpu.md
# and two `cmake --install BUILD --component runtime` folders named A and B.
#   bash bench/rank_share_ab_gpu_run.sh A B "SPP ..." ROUNDS
# (open-city-gpu.md, fourth pass: rtM rtN "256 1024" 2, rtN rtP "256 1024" 2, rtP rtQ 256 3; at
# 1024 spp one round only.)
set -e
A=$1 B=$2 SPPS=${3:-256} ROUNDS=${4:-2}
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/share.txz
field() { grep -oE "\"$1\": [0-9.e+-]+" $W/r.json | head -1 | sed 's/.*: //'; }
for v in $A $B; do for s in building city; do $W/$v/bin/exitance-relight $W/$s.bake -o $W/warm.bake --spp 16 --seed 1 --json > /dev/null; done; done
for spp in $SPPS; do for round in $(seq $ROUNDS); do for s in building city; do for sh in 0/1 0/2 1/2; do for v in $A $B; do
  [ $spp = 1024 ] && [ $round -gt 1 ] && continue
  $W/$v/bin/exitance-relight $W/$s.bake --spp $spp --seed 1 --share $sh --json > $W/r.json
  echo "$v $s spp $spp $sh: lighting_s $(field lighting_seconds) passes_s $(field passes_seconds) rays $(field rays) texels $(field texels)"
done; done; done; done; done
