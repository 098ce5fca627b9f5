#!/bin/bash
# Here (the build machine): bakes the building at 12 texels/m (1.04 M texels) and the open city at
# 1.5 texels/m (1.07 M texels), 1 spp each (only their scene.bin is used; the GPU run makes the
# converged pre-edit lighting itself), and packs them with the runtime folder, bench_bundle_rel_mse
# and the edits into .replay/refresh_change.txz for bench/refresh_change_gpu_run.sh.
#   bash bench/refresh_change_gpu_pack.sh BUILD_DIR [BAKED_BUILDING BAKED_CITY]
set -e
build=${1:-build}
work=$(mktemp -d)
building=${2:-}
city=${3:-}
if [ -z "$building" ]; then
  building=$work/building.bake city=$work/city.bake
  $build/bake/bake $build/samples/building.gltf -o $building --backend cpu --texel-density 12 --spp 1 \
    --probes none --voxel-resolution none --no-cache > /dev/null
  $build/bake/bake $build/samples/open_city.gltf -o $city --backend cpu --texel-density 1.5 --spp 1 \
    --probes none --voxel-resolution none --sky 0.5,0.6,0.8 --no-cache > /dev/null
fi
mkdir -p $work/pack/building.bake $work/pack/city.bake
cp $building/{manifest.json,scene.bin} $work/pack/building.bake/
cp $city/{manifest.json,scene.bin} $work/pack/city.bake/
cmake --install $build --component runtime --prefix $work/pack/runtime > /dev/null
cp $build/bench/bench_bundle_rel_mse $work/pack/
cp bench/refresh_move_light.json $work/pack/move.json
cp bench/refresh_double_light.json $work/pack/double.json
cp bench/refresh_move_block.json $work/pack/block.json
mkdir -p .replay
tar -C $work/pack -cf - . | xz -6 -T2 > .replay/refresh_change.txz
cp bench/refresh_change_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/refresh_change.txz
