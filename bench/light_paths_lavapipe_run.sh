#!/bin/bash
# Light subpaths in the runtime's refresh on lavapipe (this machine's CPUs, no GPU): SCENE (a sample,
# default ajar_room) baked on the CPU at 1 spp (DENSITY texels/m, default 8), relit by exitance-relight with and without
# --light-paths on at equal lighting time (TIMES seconds, --time: both modes the progressive refresh)
# and in FRAMES frames of BUDGET ms; relMSE by bench_bundle_rel_mse against two 4096-spp relights
# without subpaths (seeds 101, 202), their noise subtracted. EMITTER=1 adds, at each time, emitter
# guiding alone and with light subpaths (both whole runs: --emitter-guiding on is not progressive);
# FRAMES=0 runs no frames.
#   bash bench/light_paths_lavapipe_run.sh BUILD_DIR [WORK_DIR]   (env SCENE, DENSITY, TIMES, FRAMES, BUDGET, EMITTER)
set -e
build=${1:-build}
W=${2:-$(mktemp -d)}
mkdir -p $W
R=$build/runtime/exitance-relight
B=$W/scene.bake
$build/bake/bake $build/samples/${SCENE:-ajar_room}.gltf -o $B --backend cpu --integrator path --spp 1 --probes none \
  --voxel-resolution none --no-cache --texel-density ${DENSITY:-8} > /dev/null
common="--ignore-baked --no-light-layers --json"
$R $B -o $W/warm.bake --spp 4 --seed 1 $common > /dev/null  # lavapipe's shader cache
$R $B -o $W/warm.bake --spp 4 --seed 1 --light-paths on $common > /dev/null
for s in 101 202; do $R $B -o $W/ref_$s.bake --spp 4096 --seed $s $common > /dev/null; done
list=""
run() {  # NAME ARGS...
  local name=$1; shift
  $R $B -o $W/$name.bake --seed 3 $common "$@" > $W/$name.json
  python3 -c "
import json; r=json.load(open('$W/$name.json'))
print('$name', 'lighting_s %.3f'%r['lighting_seconds'], 'spp', r['samples_per_texel'], 'rays %.3g'%r['rays'], 'light_paths', r.get('light_paths'))"
  list="$list $W/$name.bake"
}
for t in ${TIMES:-1 4}; do
  run off_t$t --time $t
  run on_t$t --time $t --light-paths on
  if [ "${EMITTER:-0}" = 1 ]; then
    run eg_t$t --time $t --emitter-guiding on
    run egon_t$t --time $t --emitter-guiding on --light-paths on
  fi
done
if [ "${FRAMES:-6}" != 0 ]; then
  run off_f${FRAMES:-6} --frames ${FRAMES:-6} --budget-ms ${BUDGET:-100} --spp 0 --no-frame-errors
  run on_f${FRAMES:-6} --frames ${FRAMES:-6} --budget-ms ${BUDGET:-100} --spp 0 --no-frame-errors --light-paths on
fi
echo "relMSE:"
$build/bench/bench_bundle_rel_mse $W/ref_101.bake $W/ref_202.bake $list | sed "s#$W/##"
