#!/bin/bash
# Runs on the GPU machine (bench/refresh_change_gpu_pack.sh packs what it needs): the building at
# 12 texels/m and the open city at 1.5 texels/m lit to 4096 spp as the shipped bundles, then each edit refreshed frame by frame from it
# (light edits estimated as a change; docs/runtime.md) and restarted from nothing (--ignore-baked,
# the behaviour before), each output's relMSE against two 4096-spp relights of the edited scene; with
# REPS, first what the edit costs alone (`seconds.edits`, `edits.milliseconds`, waited submissions),
# REPS one-frame runs per edit; with COST_REPS, bench_edit_cost on each lit bundle (the edit and the
# one undoing it in turn, COST_REPS rounds each, one sample refreshed after each edit).
# Mode "warmdn": "warm" with --denoise (the runtime's device filter of the indirect light: every frame's
# page images and the written bundle show the filtered light; bench/results/denoise.md) and
# --page-images (each frame's page images written and timed, the filter included). Mode "warmpi":
# "warm" with --page-images alone, the same frames unfiltered. Modes "warmp32", "changep32": "warm"
# and "change" with --priority-samples 32 (the texels near a local edit get 32 samples first, not 16).
# Mode "warm": the session refreshes WARM (16) samples per texel in 16 ms frames before the edit, as an
# engine's session has when an edit comes (its passes are measured: the first frame after the edit
# is sized, not a one-sample measurement).
# Env: BUNDLES (building city), EDITS (move double block; sun is the courtyard's), FRAMES (1 6 60),
# MODES (change restart warm), REPS (0), COST_REPS (0), WARM (16), RUNTIMES (runtime: the packed
# runtime folders whose exitance-relight refreshes the frames, e.g. "runtime runtime_before"; the
# converged bases and references come from the first).
# Writes $OUT/summary.txt.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/refresh_change.txz
R=$W/runtime/bin/exitance-relight
export LD_LIBRARY_PATH=$W/runtime/lib
S=$OUT/summary.txt
$R --list-devices > $S
for b in ${BUNDLES:-building city}; do
  $R $W/$b.bake -o $W/base_$b.bake --spp 4096 --seed 7 --no-frame-errors --json > $W/base_$b.json
  python3 -c "import json; r=json.load(open('$W/base_$b.json')); print('base $b', r['spp'], 'spp', r['live_texels'], 'texels', r['seconds'])" >> $S
done
report() {  # $1 the run's JSON, $2 its label
  python3 -c "
import json; r=json.load(open('$1')); e=r['edits']; ms=[f['milliseconds'] for f in r['frames']]
pi=[f['page_images_milliseconds'] for f in r['frames'] if 'page_images_milliseconds' in f]
dn=r.get('denoise')
print('$2', 'load_s %.2f device_s %.2f'%(r['seconds']['load'], r['seconds']['load_split']['device']), ('page_images_ms first %.1f then %s'%(pi[0], sorted(round(x, 3) for x in pi[1:]))) if pi else '', ('denoise_s %.4f mean_neighbours %.1f'%(dn['seconds'], dn['mean_neighbours'])) if dn else '', 'edits_s %.4f'%r['seconds']['edits'], 'edit_ms', {k: round(v, 2) for k, v in e.get('milliseconds', {}).items()}, 'submissions', e.get('device_submissions'), 'moved_texels', e['moved_texels'], 'changed_lights', e['changed_lights'], 'frames', len(ms), 'frame_ms_sum %.1f max %.1f'%(sum(ms), max(ms)), 'over_17ms', sum(1 for m in ms if m > 17), 'spp', r['spp'], 'samples_added', [f['samples_added'] for f in r['frames']][:8])" >> $S
}
for e in ${EDITS:-move double block}; do
  b=building; [ $e = block ] && b=city; [ $e = sun ] && b=courtyard
  cp -r $W/base_$b.bake $W/base.bake.tmp && rm -rf $W/base.bake && mv $W/base.bake.tmp $W/base.bake
  if [ ${COST_REPS:-0} -gt 0 ]; then
    echo "bench_edit_cost $e:" >> $S
    $W/bench_edit_cost $W/base.bake --edits $W/$e.json --edits-back $W/${e}_back.json --repeat $COST_REPS >> $S
  fi
  for k in $(seq ${REPS:-0}); do  # the edit's cost alone, one frame, another seed each time
    $R $W/base.bake -o $W/cost.bake --edits $W/$e.json --spp 4096 --frames 1 --budget-ms 16 --seed $k --no-frame-errors --json > $W/cost.json
    report $W/cost.json ${e}_cost_$k
  done
  for s in 101 202; do $R $W/base.bake -o $W/ref_${e}_$s.bake --edits $W/$e.json --spp 4096 --seed $s --ignore-baked --json > /dev/null; done
  list=""
  for f in ${FRAMES:-1 6 60}; do
    for mode in ${MODES:-change restart}; do
      flag=""
      case $mode in
        restart) flag=--ignore-baked;;
        warm) flag="--spp-before-edits ${WARM:-16}";;
        warmpi) flag="--spp-before-edits ${WARM:-16} --page-images";;
        warmp32) flag="--spp-before-edits ${WARM:-16} --priority-samples 32";;
        changep32) flag="--priority-samples 32";;
        warmdn) flag="--spp-before-edits ${WARM:-16} --page-images --denoise";;
      esac
      for v in ${RUNTIMES:-runtime}; do
        o=${e}_${mode}_$f; [ "$v" = runtime ] || o=${o}_$v
        LD_LIBRARY_PATH=$W/$v/lib $W/$v/bin/exitance-relight $W/base.bake -o $W/$o.bake --edits $W/$e.json --spp 4096 --frames $f \
            --budget-ms 16 --seed 3 --no-frame-errors $flag --json > $W/$o.json
        report $W/$o.json $o
        list="$list $W/$o.bake"
      done
    done
  done
  echo "relMSE $e (unrefreshed = base.bake):" >> $S
  $W/bench_bundle_rel_mse $W/ref_${e}_101.bake $W/ref_${e}_202.bake $W/base.bake $list >> $S
done
cat $S
