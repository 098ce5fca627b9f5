#!/bin/bash
# Here (the build machine): bakes the building at 12 texels/m (1.04 M texels), the open city at
# 1.5 texels/m (1.07 M texels) and the courtyard at 28 texels/m (1.08 M texels) (and, when SCENES
# names them, the door-gap room ajar_room at 64 texels/m (0.36 M) and thin_walls at 128 (0.92 M),
# for bench/denoise_gpu_run.sh), 1 spp each (only
# their scene.bin is used; the GPU run makes the converged pre-edit lighting itself), and packs them
# with the runtime folder, bench_bundle_rel_mse, bench_edit_cost and the edits (each with the edit
# that undoes it, for bench_edit_cost) into .replay/refresh_change.txz for
# bench/refresh_change_gpu_run.sh.
#   bash bench/refresh_change_gpu_pack.sh BUILD_DIR [BAKED_BUILDING BAKED_CITY BAKED_COURTYARD]
# Env: SCENES (building city courtyard; also ajar_room, thin_walls): which to bake and pack; BEFORE_RUNTIME: a second runtime
# folder (e.g. `cmake --install` of an earlier commit) packed as runtime_before, for the run
# script's RUNTIMES.
set -e
build=${1:-build}
work=$(mktemp -d)
building=${2:-} city=${3:-} courtyard=${4:-}
bake() { $build/bake/bake "$@" --backend cpu --spp 1 --probes none --voxel-resolution none --no-cache > /dev/null; }
scenes=${SCENES:-building city courtyard}
wanted() { case " $scenes " in *" $1 "*) return 0;; esac; return 1; }
wanted building && { [ -n "$building" ] || { building=$work/building.bake; bake $build/samples/building.gltf -o $building --texel-density 12; }; }
wanted city && { [ -n "$city" ] || { city=$work/city.bake; bake $build/samples/open_city.gltf -o $city --texel-density 1.5 --sky 0.5,0.6,0.8; }; }
wanted courtyard && { [ -n "$courtyard" ] || { courtyard=$work/courtyard.bake; bake $build/samples/courtyard.gltf -o $courtyard --texel-density 28; }; }
wanted ajar_room && { ajar_room=$work/ajar_room.bake; bake $build/samples/ajar_room.gltf -o $ajar_room --texel-density 64; }
wanted thin_walls && { thin_walls=$work/thin_walls.bake; bake $build/samples/thin_walls.gltf -o $thin_walls --texel-density 128; }
for b in $scenes; do
  mkdir -p $work/pack/$b.bake
  eval cp \$$b/{manifest.json,scene.bin} $work/pack/$b.bake/
done
cmake --install $build --component runtime --prefix $work/pack/runtime > /dev/null
[ -z "${BEFORE_RUNTIME:-}" ] || cp -r "$BEFORE_RUNTIME" $work/pack/runtime_before
cp $build/bench/bench_bundle_rel_mse $build/bench/bench_edit_cost $work/pack/
for e in move:refresh_move_light double:refresh_double_light block:refresh_move_block sun:refresh_turn_sun; do
  cp bench/${e#*:}.json $work/pack/${e%%:*}.json
  cp bench/${e#*:}_back.json $work/pack/${e%%:*}_back.json
done
mkdir -p .replay
tar -C $work/pack -cf - . | xz -2 -T2 > .replay/refresh_change.txz
cp bench/refresh_change_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/refresh_change.txz
