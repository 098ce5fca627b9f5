#!/bin/bash
# Emitter guiding against the default next-event sampling on the GPU machine (issue 35, item 2),
# through exitance-relight (--emitter-guiding on: one guided path-traced bake of the whole lightmap,
# as bake --backend vulkan --emitter-guiding on; off: the progressive relight). Carry .gl and .replay;
# .replay/eg.txz comes from bench/emitter_guiding_gpu_pack.sh. Per bundle (BUNDLES, default every
# one packed): a two-seed 4096-spp unguided reference (seeds 101, 202), then both modes at equal
# lighting time (TIMES seconds, --time) and at equal samples (SPPS), each timed (lighting seconds,
# with the cache's build, learning and folds) and compared with the reference (bench_bundle_rel_mse:
# relMSE, the reference's noise subtracted; read_back_s: the progressive relight's download of the
# estimate, which the one-run guided mode counts in its lighting seconds, after its budget's passes). With a second runtime packed (rt_before: an A/B of a
# change), every guided run is repeated with it, alternated.
#   bash .replay/emitter_guiding_gpu_run.sh       (env BUNDLES, TIMES, SPPS, STAGES=0 for no per-stage
#                                                  runs; writes $OUT/summary.txt as it goes)
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/eg.txz
S=$OUT/summary.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $S
runtimes=rt; [ -d $W/rt_before ] && runtimes="rt_before rt"
common="--ignore-baked --no-light-layers --json"
for b in ${BUNDLES:-$(cd $W && ls -d *.bake | sed 's/\.bake$//')}; do
  B=$W/$b.bake
  R=$W/rt/bin/exitance-relight
  for rt in $runtimes; do  # shader and driver caches
    $W/$rt/bin/exitance-relight $B -o $W/warm.bake --spp 4 --seed 1 $common > /dev/null
    $W/$rt/bin/exitance-relight $B -o $W/warm.bake --spp 4 --seed 1 --emitter-guiding on $common > /dev/null
  done
  for s in 101 202; do $R $B -o $W/ref_$s.bake --spp 4096 --seed $s $common > /dev/null; done
  list=""
  run() {  # RUNTIME NAME ARGS...
    local rt=$1 name=$b-$2; shift 2
    $W/$rt/bin/exitance-relight $B -o $W/$name.bake --seed 3 $common "$@" > $W/$name.json
    python3 -c "
import json; r=json.load(open('$W/$name.json'))
print('$name', 'lighting_s %.3f'%r['lighting_seconds'], 'read_back_s %.3f'%r['seconds'].get('read_back', 0), 'spp', r['samples_per_texel'], 'rays %.3g'%r['rays'], 'rays_per_s %.3g'%r['rays_per_second'], 'guide', r.get('emitter_guiding'))" >> $S  # its setup_seconds, folds, fold_seconds: the host's part
    list="$list $W/$name.bake"
  }
  for t in ${TIMES:-0.25 1 4}; do
    run rt off_t$t --time $t
    for rt in $runtimes; do run $rt on_${rt}_t$t --time $t --emitter-guiding on; done
  done
  for n in ${SPPS:-64 256}; do
    run rt off_s$n --spp $n
    for rt in $runtimes; do run $rt on_${rt}_s$n --spp $n --emitter-guiding on; done
  done
  # Per wavefront stage at 256 spp, unguided and guided (GPU seconds beside the lighting seconds: the
  # rest is the folds' host work and idle device).
  for mode in $([ "${STAGES:-1}" = 1 ] && echo off on); do
    $R $B -o $W/stages.bake --seed 3 --spp 256 --emitter-guiding $mode --stage-statistics $common > $W/stages.json
    python3 -c "
import json; r=json.load(open('$W/stages.json')); g=sum(s['gpu_seconds'] for s in r['stages'])
print('$b stages $mode: lighting %.3f s, GPU stages %.3f s'%(r['lighting_seconds'], g))
for s in r['stages']: print('  %-50s %.4f s  rays %.3g  lanes %.2f'%(s['stage'], s['gpu_seconds'], s['rays'], s['lane_efficiency']))" >> $S
  done
  echo "$b relMSE:" >> $S
  LD_LIBRARY_PATH=$W/rt/lib $W/rt/bin/bench_bundle_rel_mse $W/ref_101.bake $W/ref_202.bake $list | sed "s#$W/##" >> $S
  rm -f $W/$b-*.bake $W/ref_*.bake -r
done
cat $S
