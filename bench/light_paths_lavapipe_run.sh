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
PREFIX=
. "$(dirname "$0")/light_paths_modes.sh"
light_paths_warm_and_references
light_paths_at_times ${TIMES:-1 4}
[ "${FRAMES:-6}" = 0 ] || light_paths_in_frames ${FRAMES:-6} ${BUDGET:-100}
echo "relMSE:"
$build/bench/bench_bundle_rel_mse $W/ref_101.bake $W/ref_202.bake $list | sed "s#$W/##"
