#!/bin/bash
# Here (the build machine): packs what bench/per_bounce_gpu_run.sh needs into .replay/pb.txz: CPU
# bakes at 1 spp of the scenes named in SCENES (cornell: the Cornell room at its default density;
# building: 12 texels/m under a sky; city: the open city at 1.7 texels/m under a sky), each with
# probes (16 spp) and the octree the gathers' leaf fallback reads, the runtime folder and
# bench_bundle_rel_mse (bench/results/per-bounce-gpu.md, "Commands").
#   SCENES="cornell building" bash bench/per_bounce_gpu_pack.sh BUILD_DIR [BAKED_DIR]
# BAKED_DIR: where the bakes go and are kept (NAME.bake); a bundle already there is reused.
set -e
build=${1:-build}
work=$(mktemp -d)
baked=${2:-$work/full}
bake() { [ -f "$3/manifest.json" ] || $build/bake/bake "$@" --backend cpu --spp 1 --probe-spp 16 --no-cache > /dev/null; }
for scene in ${SCENES:-cornell building city}; do
  case $scene in
    cornell) bake $build/samples/cornell_room.gltf -o $baked/cornell.bake ;;
    building) bake $build/samples/building.gltf -o $baked/building.bake --texel-density 12 --sky 0.6,0.7,1.0 ;;
    city) bake $build/samples/open_city.gltf -o $baked/city.bake --texel-density 1.7 --sky 0.5,0.6,0.8 ;;
    *) echo "per_bounce_gpu_pack.sh: unknown scene '$scene' (cornell, building, city)"; exit 2 ;;
  esac
  mkdir -p $work/pack/$scene.bake
  for f in manifest.json probes.bin scene.bin svo.bin; do
    [ -f $baked/$scene.bake/$f ] && cp $baked/$scene.bake/$f $work/pack/$scene.bake/
  done
done
cmake --install $build --component runtime --prefix $work/pack/rt > /dev/null
cp $build/bench/bench_bundle_rel_mse $work/pack/rt/bin/
mkdir -p .replay
tar -C $work/pack -cf - . | xz -6 -T2 > .replay/pb.txz
cp bench/per_bounce_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/pb.txz
