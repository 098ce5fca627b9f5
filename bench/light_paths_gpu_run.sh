#!/bin/bash
# Light subpaths against plain path tracing on the GPU machine (issue 35, item 3), through
# exitance-relight: with --time or --frames both modes run the progressive refresh (--light-paths on:
# its passes' texel paths connect to a pool of light subpaths per batch); with --spp alone, on is one
# path-traced run of the whole lightmap as bake --backend vulkan --light-paths on, off the progressive
# relight. Carry .gl and .replay; .replay/lp.txz (and light_paths_modes.sh, the runs it shares with
# bench/light_paths_lavapipe_run.sh) come from bench/light_paths_gpu_pack.sh.
# Per bundle (BUNDLES, default every one packed): a two-seed 4096-spp reference without subpaths
# (seeds 101, 202), then both modes at equal lighting time (TIMES seconds, --time) and at equal
# samples (SPPS), compared with the reference (bench_bundle_rel_mse: relMSE, the reference's noise
# subtracted); then per wavefront stage at 256 spp, both modes.
# Then FRAMES (default 6) frames of 16 ms each, both modes (the runtime's refresh at a game's budget).
#   bash .replay/light_paths_gpu_run.sh       (env BUNDLES, TIMES, SPPS, FRAMES, STAGES=0 for no per-stage
#                                              runs, EMITTER=1 for emitter guiding alone and with light
#                                              paths at each time; writes $OUT/summary.txt as it goes)
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
# Its own folder: a warm machine keeps other scripts' /tmp.
W=/tmp/light_paths_gpu_$$; mkdir -p $W && tar -C $W -xJf .replay/lp.txz
S=$OUT/summary.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $S
R=$W/rt/bin/exitance-relight
. "$(dirname "$0")/light_paths_modes.sh"  # packed beside this script
for b in ${BUNDLES:-$(cd $W && ls -d *.bake | sed 's/\.bake$//')}; do
  B=$W/$b.bake
  PREFIX=$b-
  light_paths_warm_and_references
  light_paths_at_times ${TIMES:-0.25 1} >> $S
  for f in ${FRAMES:-6}; do light_paths_in_frames $f 16 >> $S; done
  for n in ${SPPS:-64 256}; do
    light_paths_run off_s$n --spp $n >> $S
    light_paths_run on_s$n --spp $n --light-paths on >> $S
  done
  for mode in $([ "${STAGES:-1}" = 1 ] && echo off on); do
    $R $B -o $W/stages.bake --seed 3 --spp 256 --light-paths $mode --stage-statistics $common > $W/stages.json
    python3 -c "
import json; r=json.load(open('$W/stages.json')); g=sum(s['gpu_seconds'] for s in r['stages'])
print('$b stages $mode: lighting %.3f s, GPU stages %.3f s'%(r['lighting_seconds'], g))
for s in r['stages']: print('  %-55s %.4f s  rays %.3g  lanes %.2f'%(s['stage'], s['gpu_seconds'], s['rays'], s['lane_efficiency']))" >> $S
  done
  echo "$b relMSE:" >> $S
  LD_LIBRARY_PATH=$W/rt/lib $W/rt/bin/bench_bundle_rel_mse $W/ref_101.bake $W/ref_202.bake $list | sed "s#$W/##" >> $S
  rm -rf $W/$b-*.bake $W/ref_*.bake
done
rm -rf $W
cat $S
