#!/bin/bash
# Here (the build machine): bakes the building at 12 texels/m (1 040 336 live texels; probes and
# svo.bin as bake writes them by default) at 1 spp (the GPU run re-lights it from its scene.bin), and
# packs it with the runtime folder, bench_host_stages and, when BEFORE_RELIGHT names one, a previous
# exitance-relight to compare with, into .replay/host_stages.txz for bench/host_stages_gpu_run.sh.
#   bash bench/host_stages_gpu_pack.sh BUILD_DIR [BAKED_BUILDING]
#   BEFORE_RELIGHT=/path/to/old/exitance-relight bash bench/host_stages_gpu_pack.sh build
set -e
build=${1:-build}
work=$(mktemp -d)
building=${2:-}
if [ -z "$building" ]; then
  building=$work/building.bake
  $build/bake/bake $build/samples/building.gltf -o $building --backend cpu --texel-density 12 --spp 1 --no-cache > /dev/null
fi
mkdir -p $work/pack/building.bake
for f in manifest.json scene.bin probes.bin svo.bin; do [ -f $building/$f ] && cp $building/$f $work/pack/building.bake/; done
cmake --install $build --component runtime --prefix $work/pack/runtime > /dev/null
cp $build/bench/bench_host_stages $work/pack/
if [ -n "$BEFORE_RELIGHT" ]; then mkdir -p $work/pack/before && cp "$BEFORE_RELIGHT" $work/pack/before/exitance-relight; fi
mkdir -p .replay
tar -C $work/pack -cf - . | xz -6 -T2 > .replay/host_stages.txz
cp bench/host_stages_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/host_stages.txz
