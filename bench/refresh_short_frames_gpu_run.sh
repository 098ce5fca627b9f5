#!/bin/bash
# Runs on the GPU machine (bench/refresh_change_gpu_pack.sh packs what it needs): frames shorter
# than one sample of the lightmap. The building at 12 texels/m (1.04 M texels) and the open city
# (1.07 M texels) lit to 1024 spp, then the point light moved / the block moved and refreshed in 60
# frames of 1, 2, 4 and 16 ms: how long each frame took (a pass over part of the texels when one
# sample of them does not fit) and how many samples every texel had after 60 frames.
# Writes $OUT/summary.txt.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/refresh_change.txz
R=$W/runtime/bin/exitance-relight
export LD_LIBRARY_PATH=$W/runtime/lib
S=$OUT/summary.txt
$R --list-devices > $S
for b in building:move city:block; do
  $R $W/${b%%:*}.bake -o $W/base_${b%%:*}.bake --spp 1024 --seed 7 --no-frame-errors --json > /dev/null
  for ms in ${BUDGETS:-1 2 4 16}; do
    o=$W/${b#*:}_$ms
    $R $W/base_${b%%:*}.bake -o $o.bake --edits $W/${b#*:}.json --spp 4096 --frames 60 --budget-ms $ms --seed 3 --no-frame-errors --json > $o.json
    python3 -c "
import json; r=json.load(open('$o.json')); ms=sorted(f['milliseconds'] for f in r['frames']); n=len(ms)
print('${b#*:} budget $ms ms: frames', n, 'median %.2f p95 %.2f max %.2f ms' % (ms[n//2], ms[int(0.95*n)-1], ms[-1]), 'over budget+1:', sum(1 for m in ms if m > $ms + 1), 'samples per texel after them', r['spp'], 'first 8 frames', [round(f['milliseconds'],2) for f in r['frames'][:8]])" >> $S
  done
done
cat $S
