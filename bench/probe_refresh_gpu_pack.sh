#!/bin/bash
# Here (the build machine): the building at 12 texels/m with its probes (864 in the grid, 695 in
# use, 512 spp each on the CPU; 1 spp of lightmap: the GPU run lights it itself), the runtime
# folder, bench_edit_cost, bench_probe_rel_mse, the intensity edit, the light move and their
# undoing, into .replay/probe_refresh.txz for bench/probe_refresh_gpu_run.sh,
# bench/probe_error_gpu_run.sh and (with a bundle that has svo.bin) bench/handover_gpu_run.sh.
#   bash bench/probe_refresh_gpu_pack.sh BUILD_DIR [BAKED_BUILDING_WITH_PROBES]
set -e
build=${1:-build}
work=$(mktemp -d)
building=${2:-}
[ -n "$building" ] || { building=$work/building.bake;
  $build/bake/bake $build/samples/building.gltf -o $building --texel-density 12 --backend cpu --spp 1 \
    --voxel-resolution none --no-cache > /dev/null; }
mkdir -p $work/pack/building.bake
cp $building/{manifest.json,scene.bin,probes.bin} $work/pack/building.bake/
[ ! -f $building/svo.bin ] || cp $building/svo.bin $work/pack/building.bake/  # bench/handover_gpu_run.sh times the voxel exitance
cmake --install $build --component runtime --prefix $work/pack/runtime > /dev/null
# BEFORE_RUNTIME: another installed runtime folder, for bench/probe_error_gpu_run.sh's A/B.
rm -f .replay/probe_refresh_before.txz
if [ -n "$BEFORE_RUNTIME" ]; then mkdir -p .replay; tar -C $BEFORE_RUNTIME -cf - . | xz -2 -T2 > .replay/probe_refresh_before.txz; fi
cp $build/bench/bench_edit_cost $build/bench/bench_probe_rel_mse $work/pack/
for e in double:refresh_double_light move:refresh_move_light; do
  cp bench/${e#*:}.json $work/pack/${e%%:*}.json
  cp bench/${e#*:}_back.json $work/pack/${e%%:*}_back.json
done
mkdir -p .replay
tar -C $work/pack -cf - . | xz -2 -T2 > .replay/probe_refresh.txz
cp bench/probe_refresh_gpu_run.sh bench/probe_error_gpu_run.sh bench/handover_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/probe_refresh.txz
