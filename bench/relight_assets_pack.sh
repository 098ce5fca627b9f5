#!/bin/bash
# Here (the build machine): bakes the building and Cornell room bundles that bench/relight_assets_gpu_run.sh
# re-lights on the GPU machine, and packs them with the runtime folder into .replay/relight.txz.
# Variants: a white texture (the textured path, the same paths as the plain scene), a grey checker,
# an image sky (bench/make_equirect_sky.py), --directional sh1.
#   bash bench/relight_assets_pack.sh BUILD_DIR
set -e
build=${1:-build}
bake=$build/bake/bake
samples=$build/samples
work=$(mktemp -d)
python3 bench/make_equirect_sky.py $work/sky.hdr 1024
python3 bench/make_textured_variant.py --flat $samples/building.gltf $work/building_flat.gltf
python3 bench/make_textured_variant.py $samples/building.gltf $work/building_tex.gltf
common="--backend cpu --texel-density 8 --spp 1 --probe-spp 16"
$bake $samples/building.gltf -o $work/building.bake $common --sky 0.6,0.7,1.0
$bake $work/building_flat.gltf -o $work/building_flat.bake $common --sky 0.6,0.7,1.0
$bake $work/building_tex.gltf -o $work/building_tex.bake $common --sky 0.6,0.7,1.0
$bake $samples/building.gltf -o $work/building_sky.bake $common --sky $work/sky.hdr
$bake $samples/building.gltf -o $work/building_sh1.bake $common --sky 0.6,0.7,1.0 --directional sh1
$bake $samples/cornell_room.gltf -o $work/cornell.bake --backend cpu --texel-density 40 --spp 1 --probe-spp 16
$bake $samples/cornell_room.gltf -o $work/cornell_sh1.bake --backend cpu --texel-density 40 --spp 1 --probe-spp 16 --directional sh1
mkdir -p $work/pack
cmake --install $build --component runtime --prefix $work/pack/runtime > /dev/null
for b in building building_flat building_tex building_sky building_sh1 cornell cornell_sh1; do
  mkdir -p $work/pack/$b.bake
  cp $work/$b.bake/{manifest.json,probes.bin,scene.bin,svo.bin} $work/pack/$b.bake/
done
mkdir -p .replay
tar -C $work/pack -cf - . | xz -6 -T2 > .replay/relight.txz
cp bench/relight_assets_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/relight.txz
