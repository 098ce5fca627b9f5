#!/bin/bash
# Runs on the GPU machine (bench/edit_cost_gpu_pack.sh packs what it needs): what moving one block of
# the open city costs the caller of apply_edits, per phase. bench_edit_cost moves the block and back
# REPS rounds (one sample refreshed after each edit, SAMPLES_BEFORE per texel refreshed first); with a
# packed earlier bench_edit_cost, both in turn (before, after, before, after). Then exitance-relight
# with the block edit after WARM samples per texel in 16 ms frames, RELIGHTS times: `seconds.edits`
# and `edits.milliseconds` as an engine's call sees them.
# With a packed building, bench_edit_cost also moves its point light and back, and doubles its
# intensity and back, and doubles its warm panels' emissiveStrength and back (before and after in turn when packed).
# Env: REPS (9), ROUNDS (2: before and after in turn, this many times), SAMPLES_BEFORE (16), WARM (16), RELIGHTS (5). Writes $OUT/summary.txt.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/edit_cost.txz
export LD_LIBRARY_PATH=$W/runtime/lib
S=$OUT/summary.txt
{ nproc; lscpu | grep -i "model name"; } > $S
cost() { echo "== $1 ${2:-city} ${3:-block}" >> $S; $W/$1 $W/${2:-city}.bake --edits $W/${3:-block}.json --edits-back $W/${3:-block}_back.json \
  --repeat ${REPS:-9} --samples 1 --samples-before ${SAMPLES_BEFORE:-16} >> $S 2>&1; }
for round in $(seq ${ROUNDS:-2}); do
  for edit in block sky double_windows; do
    [ -x $W/bench_edit_cost_before ] && cost bench_edit_cost_before city $edit
    cost bench_edit_cost city $edit
  done
done
# With a packed building (BUILDING= at packing): its point light moved and its intensity doubled.
if [ -d $W/building.bake ]; then
  for round in $(seq ${ROUNDS:-2}); do
    for edit in move_light double_light double_panel; do
      [ -x $W/bench_edit_cost_before ] && cost bench_edit_cost_before building $edit
      cost bench_edit_cost building $edit
    done
  done
fi
for k in $(seq ${RELIGHTS:-5}); do
  $W/runtime/bin/exitance-relight $W/city.bake -o $W/out.bake --edits $W/block.json --spp-before-edits ${WARM:-16} \
    --frames 1 --budget-ms 16 --seed $k --no-frame-errors --json > $W/relight.json
  python3 -c "
import json; r=json.load(open('$W/relight.json')); e=r['edits']
print('relight $k edits_s %.4f'%r['seconds']['edits'], 'edit_ms', {k: round(v, 2) for k, v in e.get('milliseconds', {}).items()}, 'moved_texels', e['moved_texels'])" >> $S
done
