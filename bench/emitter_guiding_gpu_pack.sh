#!/bin/bash
# Here (the build machine): what bench/emitter_guiding_gpu_run.sh needs, packed into .replay/eg.txz:
# the building at 12 texels/m (1.04 M texels; a CPU bake at 1 spp, no probes or octree: the relights
# trace every texel from nothing), the runtime folder and bench_bundle_rel_mse.
#   bash bench/emitter_guiding_gpu_pack.sh BUILD_DIR [BUILDING_BUNDLE]   (a bundle baked as below, to reuse)
set -e
build=${1:-build}
work=$(mktemp -d)
bundle=${2:-$work/full/building.bake}
if [ -z "$2" ]; then
  $build/bake/bake $build/samples/building.gltf -o $bundle --backend cpu --integrator path --texel-density 12 \
    --spp 1 --probes none --voxel-resolution none --no-cache > /dev/null
fi
mkdir -p $work/pack/building.bake
for f in manifest.json scene.bin probes.bin svo.bin; do  # a per-bounce pack's bundle has probes and the octree too
  [ -f $bundle/$f ] && cp $bundle/$f $work/pack/building.bake/
done
cmake --install $build --component runtime --prefix $work/pack/rt > /dev/null
cp $build/bench/bench_bundle_rel_mse $work/pack/rt/bin/
mkdir -p .replay
tar -C $work/pack -cf - . | xz -6 -T2 > .replay/eg.txz
cp bench/emitter_guiding_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/eg.txz
