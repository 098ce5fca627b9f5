#!/bin/bash
# Here (the build machine): what bench/emitter_guiding_gpu_run.sh needs, packed into .replay/eg.txz:
# bundles baked on the CPU at 1 spp with no probes or octree (the relights trace every texel from
# nothing): the building at 12 texels/m (1.04 M texels; 48 rooms of lamps, point and spot lights:
# where emitter guiding gains), and with SCENES="building cornell city" also the Cornell room at 64
# texels/m and the open city at 1 texel/m (one light seen whole, sun and lit windows: where it must
# not lose); the runtime folder and bench_bundle_rel_mse; with BEFORE_BUILD (another build, e.g.
# main before a change) its runtime as rt_before, for an A/B.
#   [SCENES=...] [BEFORE_BUILD=DIR] bash bench/emitter_guiding_gpu_pack.sh BUILD_DIR [BUILDING_BUNDLE]
set -e
build=${1:-build}
work=$(mktemp -d)
bake() {  # SAMPLE NAME ARGS...
  $build/bake/bake $build/samples/$1.gltf -o $work/full/$2.bake --backend cpu --integrator path --spp 1 --probes none \
    --voxel-resolution none --no-cache "${@:3}" > /dev/null
}
for s in ${SCENES:-building}; do
  case $s in
    building) if [ -n "$2" ]; then mkdir -p $work/full && cp -r $2 $work/full/building.bake; else bake building building --texel-density 12; fi ;;
    cornell) bake cornell_room cornell --texel-density 64 ;;
    city) bake open_city city --texel-density 1 --sky 0.5,0.6,0.8 ;;
  esac
done
for b in $(cd $work/full && ls -d *.bake); do
  mkdir -p $work/pack/$b
  for f in manifest.json scene.bin probes.bin svo.bin; do  # a per-bounce pack's bundle has probes and the octree too
    [ -f $work/full/$b/$f ] && cp $work/full/$b/$f $work/pack/$b/
  done
done
cmake --install $build --component runtime --prefix $work/pack/rt > /dev/null
cp $build/bench/bench_bundle_rel_mse $work/pack/rt/bin/
[ -n "$BEFORE_BUILD" ] && cmake --install $BEFORE_BUILD --component runtime --prefix $work/pack/rt_before > /dev/null
mkdir -p .replay
tar -C $work/pack -cf - . | xz -6 -T2 > .replay/eg.txz
cp bench/emitter_guiding_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/eg.txz
