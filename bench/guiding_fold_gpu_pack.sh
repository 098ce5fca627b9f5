#!/bin/bash
# Here (the build machine): bundles and two runtime folders for bench/guiding_fold_gpu_run.sh, packed
# into .replay/gp.txz: ajar_room at 64 texels/m (the door-gap room) and the building at 12,
# baked on the CPU at 4 spp; `rt` from BUILD_DIR, `rt_before` from BEFORE_BUILD (another build of
# the runtime, e.g. main before a change) when given.
#   BEFORE_BUILD=/path/to/other/build bash bench/guiding_fold_gpu_pack.sh BUILD_DIR
set -e
build=${1:-build}
work=$(mktemp -d)
bake() { $build/bake/bake $build/samples/$1.gltf -o $work/full/$2.bake --backend cpu --integrator path --guiding off \
           --spp 4 --probe-spp 4 --no-cache "${@:3}" > /dev/null; }
bake ajar_room ajar64 --texel-density 64
bake building building12 --texel-density 12
for b in ajar64 building12; do
  mkdir -p $work/pack/$b.bake && cp $work/full/$b.bake/{manifest.json,probes.bin,scene.bin,svo.bin} $work/pack/$b.bake/
done
cmake --install $build --component runtime --prefix $work/pack/rt > /dev/null
cp $build/bench/bench_bundle_rel_mse $work/pack/rt/bin/
[ -n "$BEFORE_BUILD" ] && cmake --install $BEFORE_BUILD --component runtime --prefix $work/pack/rt_before > /dev/null
mkdir -p .replay
tar -C $work/pack -cf - . | xz -3 -T2 > .replay/gp.txz
cp bench/guiding_fold_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/gp.txz
