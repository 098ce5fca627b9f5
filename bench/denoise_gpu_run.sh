#!/bin/bash
# Runs on the GPU machine: exitance-relight with and without --denoise (bundle/indirect_denoise.h)
# on the bundles that bench/refresh_change_gpu_pack.sh packs (SCENES="building courtyard": the
# building at 12 texels/m, the courtyard at 28; with SCENES="ajar_room thin_walls city" the door-gap
# room at 64, thin_walls at 128 and the open city at 1.5), path tracing from nothing (--ignore-baked) at
# SPPS samples per texel, each output's relMSE against two 4096-spp relights (seeds 101, 202):
# the filter's error and bias on the GPU's own estimates at 1 M texels, and its host time there.
#   here: SCENES="building courtyard" bash bench/refresh_change_gpu_pack.sh build
#   there: bash .replay/denoise_gpu_run.sh        (env BUNDLES, SPPS, RUNTIME; writes $OUT/summary.txt)
# An A/B of two runtimes: BEFORE_RUNTIME=<cmake --install of the other commit> for the pack, there
#   bash .replay/denoise_gpu_run.sh; cp $OUT/summary.txt $OUT/new.txt; RUNTIME=runtime_before bash .replay/denoise_gpu_run.sh
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/refresh_change.txz
# RUNTIME=runtime_before: the pack's second runtime folder (BEFORE_RUNTIME when packing), for an A/B.
R=$W/${RUNTIME:-runtime}/bin/exitance-relight
export LD_LIBRARY_PATH=$W/${RUNTIME:-runtime}/lib
S=$OUT/summary.txt
$R --list-devices > $S
for b in ${BUNDLES:-building courtyard}; do
  for s in 101 202; do $R $W/$b.bake -o $W/ref_${b}_$s.bake --spp 4096 --seed $s --ignore-baked --no-light-layers --json > /dev/null; done
  list=""
  for n in ${SPPS:-4 16 64 256}; do
    for mode in plain denoise; do
      flag=""; [ $mode = denoise ] && flag=--denoise
      o=${b}_${mode}_$n
      $R $W/$b.bake -o $W/$o.bake --spp $n --seed 3 --ignore-baked --no-light-layers $flag --json > $W/$o.json
      python3 -c "
import json; r=json.load(open('$W/$o.json')); s=r['seconds']
print('$o', 'load_s %.2f device_s %.2f'%(s['load'], s['load_split']['device']), 'lighting_s %.3f'%s['lighting'], 'denoise_s', s.get('denoise'), 'write_s %.3f'%s['write'], 'texels', r['live_texels'], 'denoise', r.get('denoise'))" >> $S
      list="$list $W/$o.bake"
    done
  done
  echo "relMSE $b:" >> $S
  $W/bench_bundle_rel_mse --by-reference 5 $W/ref_${b}_101.bake $W/ref_${b}_202.bake $list >> $S
done
cat $S
