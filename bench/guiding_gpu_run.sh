#!/bin/bash
# Guided (grid and SVO) against unguided path tracing on the GPU machine (issue 11), through
# exitance-relight (--guiding grid|svo: one guided bake of the whole lightmap, as bake --backend vulkan).
# Carry .gl and .replay; .replay/gd.txz holds a runtime folder `rt` from
# `cmake --install BUILD --component runtime`, with build/bench/bench_bundle_rel_mse copied into rt/bin,
# and ajar.bake, cornell.bake, courtyard.bake (manifest.json, scene.bin, probes.bin, svo.bin of CPU
# bakes; bench/guiding_gpu_pack.sh makes it). Per scene: a two-seed 4096-spp unguided reference, then
# unguided, grid- and SVO-guided runs at equal lighting time (--time, TIMES seconds) and at equal
# samples (SPPS), each timed (lighting seconds, with the guides' building and learning) and compared
# with the reference (relMSE, the reference's own noise subtracted).
#   bash .replay/guiding_gpu_run.sh            (SCENES, TIMES, SPPS override the lists)
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xJf .replay/gd.txz
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R=/tmp/w/rt/bin/exitance-relight
field() { grep -o "\"$1\": *[0-9.e+-]*" $2 | head -1 | sed 's/.*: *//'; }
run() {  # NAME ARGS...: one relight, its lighting time and rays
  local name=$1; shift
  $R $B -o /tmp/w/$scene-$name.bake --seed 1 --json "$@" > /tmp/w/r.json
  echo "$scene $name: lighting $(field lighting_seconds /tmp/w/r.json) s, rays $(field rays /tmp/w/r.json)"
  tests="$tests /tmp/w/$scene-$name.bake"
}
for scene in ${SCENES:-ajar cornell courtyard}; do
  B=/tmp/w/$scene.bake
  $R $B -o /tmp/w/warm.bake --spp 4 --seed 1 --json > /dev/null                 # shader and driver caches
  $R $B -o /tmp/w/warm.bake --spp 4 --seed 1 --guiding grid --json > /dev/null
  $R $B -o /tmp/w/$scene-refA.bake --spp 4096 --seed 101 --json > /tmp/w/refA.json
  $R $B -o /tmp/w/$scene-refB.bake --spp 4096 --seed 202 --json > /tmp/w/refB.json
  echo "$scene reference: $(field lighting_seconds /tmp/w/refA.json) s per 4096-spp run"
  tests=""
  for t in ${TIMES:-0.25 1}; do
    run path-${t}s --spp 0 --time $t
    run grid-${t}s --spp 0 --time $t --guiding grid
    run svo-${t}s --spp 0 --time $t --guiding svo
  done
  for spp in ${SPPS:-256}; do
    run path-${spp}spp --spp $spp
    run grid-${spp}spp --spp $spp --guiding grid
    run svo-${spp}spp --spp $spp --guiding svo
  done
  LD_LIBRARY_PATH=/tmp/w/rt/lib /tmp/w/rt/bin/bench_bundle_rel_mse /tmp/w/$scene-refA.bake /tmp/w/$scene-refB.bake $tests | sed "s#/tmp/w/##"
  rm -rf /tmp/w/$scene-*.bake
done
