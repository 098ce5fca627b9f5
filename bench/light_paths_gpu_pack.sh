#!/bin/bash
# Here (the build machine): what bench/light_paths_gpu_run.sh needs, packed into .replay/lp.txz:
# bundles baked on the CPU at 1 spp with no probes or octree (the relights trace every texel from
# nothing): ajar_room at 64 texels/m (a lamp behind a 5 cm door gap: where light subpaths pay), and
# with SCENES="ajar building cornell" also the building at 12 texels/m (1.04 M texels) and the
# Cornell room at 64 texels/m (where they must not lose much); the runtime folder and
# bench_bundle_rel_mse.
#   [SCENES=...] bash bench/light_paths_gpu_pack.sh BUILD_DIR
set -e
build=${1:-build}
work=$(mktemp -d)
bake() {  # SAMPLE NAME ARGS...
  $build/bake/bake $build/samples/$1.gltf -o $work/full/$2.bake --backend cpu --integrator path --spp 1 --probes none \
    --voxel-resolution none --no-cache "${@:3}" > /dev/null
}
for s in ${SCENES:-ajar}; do
  case $s in
    ajar) bake ajar_room ajar --texel-density 64 ;;
    building) bake building building --texel-density 12 ;;
    cornell) bake cornell_room cornell --texel-density 64 ;;
  esac
done
for b in $(cd $work/full && ls -d *.bake); do
  mkdir -p $work/pack/$b
  cp $work/full/$b/manifest.json $work/full/$b/scene.bin $work/pack/$b/
done
cmake --install $build --component runtime --prefix $work/pack/rt > /dev/null
cp $build/bench/bench_bundle_rel_mse $work/pack/rt/bin/
mkdir -p .replay
tar -C $work/pack -cf - . | xz -6 -T2 > .replay/lp.txz
cp bench/light_paths_gpu_run.sh bench/light_paths_modes.sh .replay/
rm -rf $work
ls -la .replay/lp.txz
