#!/bin/bash
# On the GPU machine (carry .gl and .replay; bench/guiding_fold_gpu_pack.sh makes .replay/gp.txz):
# grid-guided relights with two runtimes alternated (rt_before, rt: an A/B of a guiding change, e.g.
# the fold on the host against fold_guide.comp), 3 reps at 64 and 256 spp and unguided beside them;
# then two 4096-spp unguided references and guided / unguided relights at equal time (TIMES), with
# their relMSE against the references (the references' own noise subtracted).
#   bash .replay/guiding_fold_gpu_run.sh         (BUNDLES, TIMES override the lists)
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xJf .replay/gp.txz
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
f() { python3 -c "import json; d=json.load(open('$1')); print('lighting %.4f s rays %d' % (d['lighting_seconds'], d['rays']))"; }
for b in ${BUNDLES:-ajar64 building12}; do
  B=/tmp/w/$b.bake
  for rt in rt_before rt; do /tmp/w/$rt/bin/exitance-relight $B -o /tmp/w/o.bake --spp 4 --guiding grid --json > /dev/null; done
  for rep in 1 2 3; do
    for rt in rt_before rt; do
      for args in "--spp 64 --guiding grid" "--spp 256 --guiding grid" "--spp 256 --guiding off"; do
        [ "$rt" = rt_before ] && [ "$args" = "--spp 256 --guiding off" ] && continue
        /tmp/w/$rt/bin/exitance-relight $B -o /tmp/w/o.bake $args --seed 1 --json > /tmp/w/r.json
        echo "$b $rt $args rep $rep: $(f /tmp/w/r.json)"
      done
    done
  done
  R=/tmp/w/rt/bin/exitance-relight
  $R $B -o /tmp/w/refA.bake --spp 4096 --seed 101 --json > /dev/null
  $R $B -o /tmp/w/refB.bake --spp 4096 --seed 202 --json > /dev/null
  tests=""
  for t in ${TIMES:-0.25 1}; do
    for g in off grid; do
      for rt in rt_before rt; do
        [ "$rt" = rt_before ] && [ $g = off ] && continue
        /tmp/w/$rt/bin/exitance-relight $B -o /tmp/w/$b-$rt-$g-$t.bake --spp 0 --time $t --guiding $g --seed 1 --json > /tmp/w/r.json
        echo "$b $rt --guiding $g --time $t: $(f /tmp/w/r.json)"; tests="$tests /tmp/w/$b-$rt-$g-$t.bake"
      done
    done
  done
  LD_LIBRARY_PATH=/tmp/w/rt/lib /tmp/w/rt/bin/bench_bundle_rel_mse /tmp/w/refA.bake /tmp/w/refB.bake $tests | sed "s#/tmp/w/##"
  rm -rf /tmp/w/$b-*.bake /tmp/w/ref?.bake
done
