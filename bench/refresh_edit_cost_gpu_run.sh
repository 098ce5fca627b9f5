#!/bin/bash
# Runs on the GPU machine (bench/refresh_change_gpu_pack.sh packs what it needs): what an edit costs
# from the call to its return (`seconds.edits`, split in `edits.milliseconds`, with the device
# submissions it waited for), REPS times per edit on the building (light edits, 4096-spp base) and the
# open city (the block move), and the block move's relMSE after 1, 6 and 60 frames of 16 ms against two
# 4096-spp relights of the edited city (bench_bundle_rel_mse). Env: REPS (3), FRAMES (1 6 60).
# Writes $OUT/summary.txt.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/refresh_change.txz
R=$W/runtime/bin/exitance-relight
export LD_LIBRARY_PATH=$W/runtime/lib
S=$OUT/summary.txt
$R --list-devices > $S
for b in building city; do
  $R $W/$b.bake -o $W/base_$b.bake --spp 4096 --seed 7 --no-frame-errors --json > $W/base_$b.json
  python3 -c "import json; r=json.load(open('$W/base_$b.json')); print('base $b', r['spp'], 'spp', r['live_texels'], 'texels', r['seconds'])" >> $S
done
report() {
  python3 -c "
import json; r=json.load(open('$1')); e=r['edits']; ms=[f['milliseconds'] for f in r['frames']]
print('$2', 'edits_s %.4f'%r['seconds']['edits'], 'edit_ms', {k: round(v, 2) for k, v in e.get('milliseconds', {}).items()}, 'submissions', e.get('device_submissions'), 'moved_texels', e['moved_texels'], 'changed_lights', e['changed_lights'], 'frames', len(ms), 'frame_ms_sum %.1f max %.1f'%(sum(ms), max(ms)), 'over_17ms', sum(1 for m in ms if m > 17))" >> $S
}
for e in move double block; do
  b=building; [ $e = block ] && b=city
  for k in $(seq ${REPS:-3}); do
    $R $W/base_$b.bake -o $W/cost.bake --edits $W/$e.json --spp 4096 --frames 1 --budget-ms 16 --seed $k --no-frame-errors --json > $W/cost.json
    report $W/cost.json ${e}_cost_$k
  done
done
for s in 101 202; do $R $W/base_city.bake -o $W/ref_$s.bake --edits $W/block.json --spp 4096 --seed $s --ignore-baked --json > /dev/null; done
list=""
for f in ${FRAMES:-1 6 60}; do
  $R $W/base_city.bake -o $W/block_$f.bake --edits $W/block.json --spp 4096 --frames $f --budget-ms 16 --seed 3 --no-frame-errors --json > $W/block_$f.json
  report $W/block_$f.json block_change_$f
  list="$list $W/block_$f.bake"
done
echo "relMSE block (unrefreshed = base_city.bake):" >> $S
$W/bench_bundle_rel_mse $W/ref_101.bake $W/ref_202.bake $W/base_city.bake $list >> $S
cat $S
