#!/bin/bash
# `bake --integrator path --spp 0 --time T` on the CPU three ways, two seeds each, against two converged
# bakes (light subpaths on every sample, seeds 101 and 202), relMSE per texel by bench_bundle_rel_mse:
#   default: --guiding auto with its candidate from the scene (light subpaths where any light starts
#            them: emitters, punctual lights, the sky), --light-paths auto;
#   lpoff:   --light-paths off (--guiding auto measures grid guiding: the default before issue 35 item 4);
#   off:     --light-paths off --guiding off (unguided; emitter guiding and adaptive sampling as default).
# Usage: bash bench/equal_time_guiding_auto.sh BUILD_DIR SCENE DENSITY REFERENCE_SPP SECONDS [WORK_DIR]
# (bench/results/guiding-auto-light-paths.md). References are kept in WORK_DIR and reused.
# BAKE_EXTRA: options for every bake (e.g. BAKE_EXTRA="--sky 0.8,0.85,1.0" for the outdoor samples).
set -e
build=$1; scene=$2; density=$3; reference_spp=$4; seconds=$5
work=${6:-/tmp/equal_time_guiding_auto}/$(basename $scene .gltf)
mkdir -p $work
common="--texel-density $density --probes none --voxel-resolution none --no-cache --seams off $BAKE_EXTRA"
for seed in 101 202; do
  [ -f $work/ref$seed.bake/manifest.json ] ||
    $build/bake/bake $scene -o $work/ref$seed.bake $common --integrator path --light-paths on --guiding off \
      --spp $reference_spp --seed $seed > /dev/null 2>&1
done
for mode in default lpoff off; do
  case $mode in default) extra="";; lpoff) extra="--light-paths off";; off) extra="--light-paths off --guiding off";; esac
  for seed in 1 2; do
    $build/bake/bake $scene -o $work/$mode$seed.bake $common --integrator path --spp 0 --time $seconds --seed $seed $extra > /dev/null 2>&1
    python3 -c "
import json; s = json.load(open('$work/$mode$seed.bake/manifest.json'))['stats']; g = s.get('guiding', {})
print('$mode seed $seed: candidate', g.get('candidate'), 'chose', g.get('chose'), 'dropped', g.get('pilot_samples_dropped'),
      'spp mean %.0f' % s['samples_per_texel']['mean'])"
  done
done
$build/bench/bench_bundle_rel_mse $work/ref101.bake $work/ref202.bake $work/{default,lpoff,off}{1,2}.bake
