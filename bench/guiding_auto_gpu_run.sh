#!/bin/bash
# `--guiding auto` against unguided path tracing on the GPU machine (issue 35, item 4's goal: within
# 5 % of unguided on the Cornell room, the courtyard and the open city), through exitance-relight
# (--guiding auto: bake --backend vulkan --guiding auto's pilot and choice as one whole run).
# Carry .gl and .replay; .replay/ga.txz comes from bench/guiding_auto_gpu_pack.sh. Per scene: a
# two-seed 4096-spp unguided reference, then unguided and auto runs at equal lighting time (--time,
# TIMES seconds) and at equal samples (SPPS), each timed (lighting seconds, pilot included) with what
# auto chose, and compared with the reference (relMSE, the reference's own noise subtracted). "off" is
# the refresh calls' unguided run, "whole" the unguided whole run (--whole-run) that bake --backend
# vulkan makes and that auto's whole runs compare with on equal terms.
# Writes $OUT/summary.txt.
#   bash .replay/guiding_auto_gpu_run.sh        (SCENES, TIMES, SPPS override the lists; STAGES=1 adds
#                                                the GPU seconds per stage at the largest SPPS)
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xJf .replay/ga.txz
S=$OUT/summary.txt
TIMES=${TIMES:-0.25 1 4}
SPPS=${SPPS:-256 1024}
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc; } > $S
R=/tmp/w/rt/bin/exitance-relight
run() {  # NAME ARGS...: one relight, its lighting time, samples and what auto chose
  local name=$1; shift
  $R $B -o /tmp/w/$scene-$name.bake --seed 1 --json "$@" > /tmp/w/r.json
  python3 -c "
import json; r=json.load(open('/tmp/w/r.json')); g=r.get('guiding_auto')
c='' if g is None else ' auto: candidate %s decided %s abandoned_at %s chose %s pilot %s texels_guided %.4f regions %s/%s scene_ratio %s setup %s s' % (g.get('candidate'), g.get('decided'), g.get('abandoned_at_samples_per_texel'), g.get('chose'), g.get('pilot_samples_per_texel'), g.get('texels_guided_fraction', 0), g.get('regions_guided'), g.get('regions'), g.get('efficiency_ratio', {}).get('scene'), g.get('setup_seconds'))
print('$scene $name: lighting %.3f s, spp %s, rays %s, whole %.2f s%s' % (r['lighting_seconds'], r['spp'], r['rays'], sum(v for v in r['seconds'].values() if isinstance(v, (int, float))), c))" >> $S
  tests="$tests /tmp/w/$scene-$name.bake"
}
for scene in ${SCENES:-cornell courtyard city ajar}; do
  B=/tmp/w/$scene.bake
  $R $B -o /tmp/w/warm.bake --spp 4 --seed 1 --json > /dev/null                 # shader and driver caches
  $R $B -o /tmp/w/warm.bake --spp 4 --seed 1 --light-paths on --json > /dev/null  # the light-subpath kernels
  $R $B -o /tmp/w/$scene-refA.bake --spp 4096 --seed 101 --json > /dev/null
  $R $B -o /tmp/w/$scene-refB.bake --spp 4096 --seed 202 --json > /dev/null
  tests=""
  for t in $TIMES; do
    run off-${t}s --spp 0 --time $t
    run whole-${t}s --spp 0 --time $t --whole-run
    run auto-${t}s --spp 0 --time $t --guiding auto
  done
  for spp in $SPPS; do
    run off-${spp}spp --spp $spp
    run whole-${spp}spp --spp $spp --whole-run
    run auto-${spp}spp --spp $spp --guiding auto
  done
  # Where a whole run's GPU time goes (STAGES=1): the stages' GPU seconds of the unguided whole run and
  # auto at the largest --spp.
  if [ -n "${STAGES:-}" ]; then
    for mode in "--whole-run" "--guiding auto"; do
      $R $B -o /tmp/w/stages.bake --spp ${SPPS##* } --seed 1 --stage-statistics --json $mode > /tmp/w/s.json
      python3 -c "
import json; r=json.load(open('/tmp/w/s.json'))
st=' '.join('%s %.3f' % (s['stage'], s['gpu_seconds']) for s in r.get('stages', []))
print('$scene stages ${SPPS##* }spp $mode: lighting %.3f s, GPU %.3f s: %s' % (r['lighting_seconds'], sum(s['gpu_seconds'] for s in r.get('stages', [])), st))" >> $S
    done
  fi
  LD_LIBRARY_PATH=/tmp/w/rt/lib /tmp/w/rt/bin/bench_bundle_rel_mse /tmp/w/$scene-refA.bake /tmp/w/$scene-refB.bake $tests | sed "s#/tmp/w/##" >> $S
  rm -rf /tmp/w/$scene-*.bake
done
cat $S
