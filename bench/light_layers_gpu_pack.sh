#!/bin/bash
# Here (the build machine): packs the building at 12 texels/m (1.04 M texels; 1 spp, only its
# scene.bin is used: the GPU run makes the converged pre-edit lighting itself), the runtime folder,
# bench_bundle_rel_mse, bench_edit_cost and the intensity / light-move edits (each with the edit that
# undoes it) into .replay/light_layers.txz for bench/light_layers_gpu_run.sh.
#   bash bench/light_layers_gpu_pack.sh BUILD_DIR [BAKED_BUILDING]
set -e
build=${1:-build}
work=$(mktemp -d)
building=${2:-}
[ -n "$building" ] || { building=$work/building.bake;
  $build/bake/bake $build/samples/building.gltf -o $building --texel-density 12 --backend cpu --spp 1 --probes none \
    --voxel-resolution none --no-cache > /dev/null; }
mkdir -p $work/pack/building.bake
cp $building/{manifest.json,scene.bin} $work/pack/building.bake/
cmake --install $build --component runtime --prefix $work/pack/runtime > /dev/null
cp $build/bench/bench_bundle_rel_mse $build/bench/bench_edit_cost $work/pack/
for e in move:refresh_move_light double:refresh_double_light; do
  cp bench/${e#*:}.json $work/pack/${e%%:*}.json
  cp bench/${e#*:}_back.json $work/pack/${e%%:*}_back.json
done
mkdir -p .replay
tar -C $work/pack -cf - . | xz -2 -T2 > .replay/light_layers.txz
cp bench/light_layers_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/light_layers.txz
