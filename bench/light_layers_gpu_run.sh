#!/bin/bash
# Runs on the GPU machine (bench/light_layers_gpu_pack.sh packs what it needs): the building at 12
# texels/m lit to 4096 spp as the shipped bundle, then one point light's intensity doubled
# (bench/refresh_double_light.json) and refreshed frame by frame: right at open ("open": the bundle
# holds no light layers and the accumulation has no split yet, so the edit is a change estimate as
# without layers) and in a session that has refreshed WARM samples per texel first ("warm": a game
# running when the edit comes; the layers are scaled with 0 rays, the baked texels by the
# accumulation's split), with light layers and without (--no-light-layers: a change estimate), each
# output's relMSE against two 4096-spp relights of the edited scene; the light move with and without
# layers; the throughput with and without layers (one unbudgeted frame of 256 spp); bench_edit_cost on the lit
# bundle after WARM samples (the edit and the one undoing it in turn, COST_REPS rounds).
# Mode "bundle": the edit right at open of a bundle lit to 4096 spp with --light-layers (it holds its
# layers: docs/bundle.md "Light layers"), so the first frame shows the lit bundle with that layer
# scaled; with it, that bundle's write time and size and bench_edit_cost on it with no sample before.
# Env: WARM (256), FRAMES (1 6), EDITS (double move), MODES (open warm open-nolayers warm-nolayers),
# COST_REPS (9), THROUGHPUT (1: the two throughput runs). Writes $OUT/summary.txt.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/light_layers.txz
R=$W/runtime/bin/exitance-relight
export LD_LIBRARY_PATH=$W/runtime/lib
S=$OUT/summary.txt
$R --list-devices > $S
$R $W/building.bake -o $W/base.bake --spp 4096 --seed 7 --no-frame-errors --json > $W/base.json
python3 -c "import json; r=json.load(open('$W/base.json')); print('base', r['spp'], 'spp', r['seconds'], 'light_layers', r['light_layers'])" >> $S
modes=${MODES:-open warm open-nolayers warm-nolayers}
if [[ " $modes " == *" bundle "* ]]; then
  $R $W/building.bake -o $W/base_layers.bake --spp 4096 --seed 7 --light-layers --no-frame-errors --json > $W/base_layers.json
  python3 -c "import json; r=json.load(open('$W/base_layers.json')); print('base with --light-layers', r['spp'], 'spp', r['seconds'], 'light_layers', r['light_layers'], 'bundle_light_layers', r.get('bundle_light_layers'))" >> $S
  grep -o '"light_layers": {[^}]*}' $W/base_layers.bake/manifest.json | head -1 >> $S
  du -sb $W/base.bake $W/base_layers.bake $W/base_layers.bake/light-layers-0.exr $W/base_layers.bake/lightmap-0.exr >> $S
fi
for layers in $([ "${THROUGHPUT:-1}" = 1 ] && echo on off); do
  flag=""; [ $layers = off ] && flag=--no-light-layers
  $R $W/building.bake -o $W/tp.bake --spp 256 --frames 1 --seed 9 --no-frame-errors $flag --json > $W/tp.json
  python3 -c "import json; r=json.load(open('$W/tp.json')); print('one frame of 256 spp, light layers $layers:', r['light_layers'], 'lighting_s %.3f'%r['lighting_seconds'], 'rays/s %.3g'%r['rays_per_second'])" >> $S
done
report() {  # $1 the run's JSON, $2 its label
  python3 -c "
import json; r=json.load(open('$1')); e=r['edits']; ms=[f['milliseconds'] for f in r['frames']]
print('$2', 'edits_s %.5f'%r['seconds']['edits'], 'edit_ms', {k: round(v, 3) for k, v in e.get('milliseconds', {}).items()}, 'scaled', e.get('scaled_light_layers'), 'changed_lights', e['changed_lights'], 'samples_before', e.get('samples_before', 0), 'frames', len(ms), 'frame_ms', [round(m, 1) for m in ms], 'spp', r['spp'], 'light_layers', r['light_layers'])" >> $S
}
for e in ${EDITS:-double move}; do
  for s in 101 202; do $R $W/base.bake -o $W/ref_${e}_$s.bake --edits $W/$e.json --spp 4096 --seed $s --ignore-baked --no-light-layers --json > /dev/null; done
  list=""
  for f in ${FRAMES:-1 6}; do
    for mode in $modes; do
      flags=""; input=$W/base.bake
      [ $mode = bundle ] && input=$W/base_layers.bake
      case $mode in warm*) flags="--spp-before-edits ${WARM:-256}";; esac
      case $mode in *nolayers) flags="$flags --no-light-layers";; esac
      case "$e/$mode" in move/warm*) continue;; esac
      o=${e}_${mode}_$f
      $R $input -o $W/$o.bake --edits $W/$e.json --spp 4096 --frames $f --budget-ms 16 --seed 3 --no-frame-errors $flags --json > $W/$o.json
      report $W/$o.json $o
      list="$list $W/$o.bake"
    done
  done
  echo "relMSE $e (unrefreshed = base.bake):" >> $S
  $W/bench_bundle_rel_mse $W/ref_${e}_101.bake $W/ref_${e}_202.bake $W/base.bake $list >> $S
done
echo "bench_edit_cost double after ${WARM:-256} samples (light layers on by default):" >> $S
[ "${COST_REPS:-9}" = 0 ] || $W/bench_edit_cost $W/base.bake --edits $W/double.json --edits-back $W/double_back.json --repeat ${COST_REPS:-9} --samples-before ${WARM:-256} >> $S
if [[ " $modes " == *" bundle "* ]]; then
  echo "bench_edit_cost double at open of the bundle with light layers (no sample before):" >> $S
  $W/bench_edit_cost $W/base_layers.bake --edits $W/double.json --edits-back $W/double_back.json --repeat 9 --samples-before 0 >> $S
fi
cat $S
