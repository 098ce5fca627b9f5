#!/bin/bash
# Here (the build machine): packs what bench/edit_cost_gpu_run.sh needs into .replay/edit_cost.txz:
# the open city at 1.5 texels/m (1.07 M texels; baked at 1 spp unless a bundle is given), the
# runtime component, bench_edit_cost, the city block's edit and the one undoing it (and its sky's and lit
# windows' edits), and optionally a
# second bench_edit_cost built from an earlier commit (BEFORE=path/to/bench_edit_cost) for an A/B on
# the same host. BUILDING=path/to/building.bake (a bake of samples/building.gltf, e.g. at 12 texels/m as
# bench/per_bounce_gpu_pack.sh makes it) adds it with the point light's move and intensity edits and
# its warm panels' emissiveStrength doubled.
#   bash bench/edit_cost_gpu_pack.sh BUILD_DIR [CITY_BUNDLE]
set -e
build=${1:-build}
work=$(mktemp -d)
city=${2:-}
if [ -z "$city" ]; then
  city=$work/city.bake
  $build/bake/bake $build/samples/open_city.gltf -o $city --texel-density 1.5 --sky 0.5,0.6,0.8 --backend cpu --spp 1 \
    --probes none --voxel-resolution none --no-cache > /dev/null
fi
mkdir -p $work/pack/city.bake
cp $city/{manifest.json,scene.bin} $work/pack/city.bake/
cmake --install $build --component runtime --prefix $work/pack/runtime > /dev/null
cp $build/bench/bench_edit_cost $work/pack/
[ -z "${BEFORE:-}" ] || cp "$BEFORE" $work/pack/bench_edit_cost_before
cp bench/refresh_move_block.json $work/pack/block.json
cp bench/refresh_move_block_back.json $work/pack/block_back.json
# The city's sky changed (a constant sky: its layer scaled) and its lit windows' material doubled.
for e in sky sky_back double_windows double_windows_back; do cp bench/refresh_$e.json $work/pack/$e.json; done
if [ -n "${BUILDING:-}" ]; then
  mkdir -p $work/pack/building.bake
  for f in manifest.json scene.bin probes.bin svo.bin; do [ -f $BUILDING/$f ] && cp $BUILDING/$f $work/pack/building.bake/; done
  for e in move_light move_light_back double_light double_light_back double_panel double_panel_back; do cp bench/refresh_$e.json $work/pack/$e.json; done
fi
mkdir -p .replay
tar -C $work/pack -cf - . | xz -2 -T2 > .replay/edit_cost.txz
cp bench/edit_cost_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/edit_cost.txz
