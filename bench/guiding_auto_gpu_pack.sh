#!/bin/bash
# Here (the build machine): the bundles and runtime folder bench/guiding_auto_gpu_run.sh needs, packed
# into .replay/ga.txz: the Cornell room and ajar_room at 64 texels/m, the courtyard at 28 and the
# open city at 1.5 (0.4-1.1 M texels each), baked on the CPU at 1 spp, their manifest
# and scene.bin only, with the runtime component and bench_bundle_rel_mse.
#   bash bench/guiding_auto_gpu_pack.sh BUILD_DIR
set -e
build=${1:-build}
work=$(mktemp -d)
bake() { $build/bake/bake $build/samples/$1.gltf -o $work/full/$2.bake --backend cpu --integrator path --guiding off \
           --probes none --voxel-resolution none --no-cache "${@:3}" > /dev/null; }
bake cornell_room cornell --texel-density 64 --spp 1
bake ajar_room ajar --texel-density 64 --spp 1
bake courtyard courtyard --texel-density 28 --sky 0.5,0.6,0.8 --spp 1
bake open_city city --texel-density 1.5 --sky 0.5,0.6,0.8 --spp 1
for b in cornell ajar courtyard city; do
  mkdir -p $work/pack/$b.bake && cp $work/full/$b.bake/{manifest.json,scene.bin} $work/pack/$b.bake/
done
cmake --install $build --component runtime --prefix $work/pack/rt > /dev/null
cp $build/bench/bench_bundle_rel_mse $work/pack/rt/bin/
mkdir -p .replay
tar -C $work/pack -cf - . | xz -6 -T2 > .replay/ga.txz
cp bench/guiding_auto_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/ga.txz
