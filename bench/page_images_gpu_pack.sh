#!/bin/bash
# Here (the build machine): packs samples/engine_sample's program and the building's glTF into
# .replay/engine_sample.txz for bench/page_images_gpu_run.sh, which runs after
# bench/refresh_change_gpu_run.sh on the same machine (it reuses that run's runtime folder and its
# 4096-spp building bundle). Run bench/refresh_change_gpu_pack.sh too.
#   bash bench/page_images_gpu_pack.sh BUILD_DIR
set -e
build=${1:-build}
work=$(mktemp -d)
cp $build/samples/engine_sample/exitance_engine_sample $build/samples/building.gltf $build/samples/building.bin $work/
cp -P $build/runtime/loader/libexitance_loader.so* $work/  # the sample links the loader's shared library too
cp -L /lib/x86_64-linux-gnu/libtinygltf.so.2d /lib/x86_64-linux-gnu/libstb.so.0 $work/  # and Debian's tinygltf and stb
mkdir -p .replay
tar -C $work -cf - . | xz -2 -T2 > .replay/engine_sample.txz
cp bench/page_images_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/engine_sample.txz
