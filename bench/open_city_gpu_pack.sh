#!/bin/bash
# Here (the build machine): bakes the open-city bundle that bench/open_city_gpu_run.sh re-lights on
# the GPU machine (1 310 496 live texels at --texel-density 1.7; scene.bin 120 MB), and packs it with
# the runtime folder into .replay/city.txz (11 MB).
#   bash bench/open_city_gpu_pack.sh BUILD_DIR
set -e
build=${1:-build}
work=$(mktemp -d)
$build/bake/bake $build/samples/open_city.gltf -o $work/city.bake --backend cpu --texel-density 1.7 --spp 1 \
  --probe-spp 16 --sky 0.5,0.6,0.8 --no-cache > /dev/null
mkdir -p $work/pack/city.bake
cp $work/city.bake/{manifest.json,probes.bin,scene.bin,svo.bin} $work/pack/city.bake/
cmake --install $build --component runtime --prefix $work/pack/runtime > /dev/null
mkdir -p .replay
tar -C $work/pack -cf - . | xz -6 -T2 > .replay/city.txz
cp bench/open_city_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/city.txz
