#!/bin/bash
# Runs on the GPU machine (bench/probe_refresh_gpu_pack.sh BUILD BUNDLE_WITH_SVO packs what it
# needs): what handing the results over on the device costs per frame (docs/runtime.md "Results on
# the device", "Probes", "Voxel exitance"). The building at 12 texels/m lit to 1024 spp with light
# layers, then for each edit (EDITS: double move) 32 warm samples per texel, the edit and 30 frames of
# 16 ms with --page-images (the page images, the probe buffer and the voxel exitance written after
# each frame, outside its time) and no per-frame read-backs. Writes $OUT/summary.txt.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/probe_refresh.txz
R=$W/runtime/bin/exitance-relight
export LD_LIBRARY_PATH=$W/runtime/lib
S=$OUT/summary.txt
$R --list-devices > $S
$R $W/building.bake -o $W/lit.bake --spp 1024 --seed 7 --light-layers --no-frame-errors --json > $W/lit.json
for e in ${EDITS:-double move}; do
  $R $W/lit.bake -o $W/h_$e.bake --spp-before-edits 32 --edits $W/$e.json --frames 30 --budget-ms 16 --seed 3 --page-images --no-frame-errors --json > $W/h_$e.json
  python3 -c "
import json; r=json.load(open('$W/h_$e.json')); fr=r['frames']
def stats(k):
  v=sorted(f[k] for f in fr[1:] if k in f); return 'median %.3f min %.3f max %.3f (frames 2-30), first %.1f' % (v[len(v)//2], v[0], v[-1], fr[0].get(k, float('nan'))) if v else 'none'
ms=sorted(f['milliseconds'] for f in fr)
print('$e: frame ms median %.2f p95 %.2f, over 17 ms %d of %d' % (ms[len(ms)//2], ms[int(0.95*(len(ms)-1))], sum(m > 17 for m in ms), len(ms)))
for k in ['page_images_milliseconds', 'probe_buffer_milliseconds', 'voxel_exitance_milliseconds']: print('  ', k, stats(k))" >> $S
done
cat $S
