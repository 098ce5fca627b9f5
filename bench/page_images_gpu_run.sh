#!/bin/bash
# Runs on the GPU machine after bench/refresh_change_gpu_run.sh (its /tmp/w): what handing the
# lightmap pages to an engine on the device costs per frame (exitance-relight --page-images on the
# building's 4096-spp bundle, 1.04 M texels, 16 ms frames, after the point light moved), and
# samples/engine_sample drawing the building's room 0_0_2 from those images while its light moves
# (6 frames, 4 samples per frame), its strip in $OUT/engine_strip.png. Appends to $OUT/summary.txt.
set -e
W=/tmp/w; R=$W/runtime/bin/exitance-relight; S=$OUT/summary.txt
export LD_LIBRARY_PATH=$W/runtime/lib:$W
tar -C $W -xJf .replay/engine_sample.txz
$R $W/base_building.bake -o $W/pi.bake --edits $W/move.json --spp 4096 --frames 30 --budget-ms 16 --seed 5 \
   --no-frame-errors --page-images --json > $W/pi.json
python3 -c "
import json; r=json.load(open('$W/pi.json')); f=r['frames']
pi=sorted(x['page_images_milliseconds'] for x in f[1:]); ms=[x['milliseconds'] for x in f]
print('page_images building', r['live_texels'], 'texels, first call %.2f ms, then median %.3f ms, range %.3f-%.3f ms over %d frames; frame ms median %.1f' % (f[0]['page_images_milliseconds'], pi[len(pi)//2], pi[0], pi[-1], len(pi), sorted(ms)[len(ms)//2]))" >> $S
cp -r $W/base_building.bake $W/engine.bake
( time $W/exitance_engine_sample $W/building.gltf $W/engine.bake Room_0_0_2_Point 2.7,2.2,13.1 4.2,2.2,12.0 \
   --look-from 0.7,1.6,11.0 --look-at 4.6,0.9,14.8 --yfov 1.2 --size 480,360 --frames 6 --samples 4 \
   -o $OUT/engine_strip.png ) >> $S 2>&1
tail -20 $S
