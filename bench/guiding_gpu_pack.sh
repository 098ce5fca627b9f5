#!/bin/bash
# Here (the build machine): the bundles and runtime folder bench/guiding_gpu_run.sh needs, packed into
# .replay/gd.txz. Densities 4x those of bench/run_time_vs_error.py (so a GPU has work: 16x the
# texels), baked on the CPU at 16 spp (their svo.bin exitance seeds --guiding svo's first fields).
#   bash bench/guiding_gpu_pack.sh BUILD_DIR
set -e
build=${1:-build}
work=$(mktemp -d)
bake() { $build/bake/bake $build/samples/$1.gltf -o $work/full/$2.bake --backend cpu --integrator path --guiding off \
           --spp 16 --probe-spp 16 --no-cache "${@:3}" > /dev/null; }
bake ajar_room ajar --texel-density 16
bake cornell_room cornell --texel-density 16
bake courtyard courtyard --texel-density 8 --sky 0.5,0.6,0.8
for b in ajar cornell courtyard; do
  mkdir -p $work/pack/$b.bake && cp $work/full/$b.bake/{manifest.json,probes.bin,scene.bin,svo.bin} $work/pack/$b.bake/
done
cmake --install $build --component runtime --prefix $work/pack/rt > /dev/null
cp $build/bench/bench_bundle_rel_mse $work/pack/rt/bin/
mkdir -p .replay
tar -C $work/pack -cf - . | xz -6 -T2 > .replay/gd.txz
cp bench/guiding_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/gd.txz
