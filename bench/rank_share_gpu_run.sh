#!/bin/bash
# On the GPU machine (device tool, carry [".gl", ".replay"]): main's end-to-end throughput, its
# stages, and how a split bake's ranks balance, measured on one GPU with exitance-relight --share R/N
# (each rank's share alone; what two GPUs would take is the slower rank's time).
# Packed here (.replay/share.txz): the building and open-city bundles of
# bench/results/open-city-gpu.md ("Spatial splits" section) and main's runtime folder (rtM, from
# `cmake --install BUILD --component runtime`). Prints one line per run.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/share.txz
R=$W/rtM/bin/exitance-relight
field() { grep -oE "\"$1\": [0-9.e+-]+" $W/r.json | head -1 | sed 's/.*: //'; }
for s in building city; do $R $W/$s.bake -o $W/warm.bake --spp 16 --seed 1 --json > /dev/null; done
for round in 1 2 3; do for s in building city; do
  $R $W/$s.bake -o $W/o.bake --spp 256 --seed 1 --json > $W/r.json
  echo "throughput $s: lighting_s $(field lighting_seconds) rays_per_s $(field rays_per_second) md5 $(md5sum < $W/o.bake/lightmap-0.exr | cut -c1-8)"
done; done
for s in building city; do
  $R $W/$s.bake -o $W/o.bake --spp 256 --seed 1 --json --stage-statistics --traversal-rays 16777216 > $W/r.json
  echo "stages $s: traversal_only $(field traversal_only_rays_per_second)"
  tr -d ' \n' < $W/r.json | grep -oE '"stages":\[[^]]*\]' | sed 's/"items":[0-9]*,//g; s/"rays":[0-9]*,//g' | cut -c1-1200; echo
done
for spp in 256 1024; do for round in 1 2; do for s in building city; do for sh in 0/1 0/2 1/2; do
  [ $spp = 1024 ] && [ $round = 2 ] && continue
  $R $W/$s.bake --spp $spp --seed 1 --share $sh --json > $W/r.json
  echo "share $s spp $spp $sh: lighting_s $(field lighting_seconds) passes_s $(field passes_seconds) rays $(field rays)"
done; done; done; done
for s in building city; do for T in 1 4; do
  $R $W/$s.bake -o $W/o.bake --spp 0 --time $T --seed 1 --integrator bounces --json > $W/r.json
  echo "bounces $s --time $T: lighting_s $(field lighting_seconds) spp $(field spp)"
done; done
