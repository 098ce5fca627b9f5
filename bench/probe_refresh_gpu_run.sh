#!/bin/bash
# Runs on the GPU machine (bench/probe_refresh_gpu_pack.sh packs what it needs): the building at 12
# texels/m lit to 1024 spp with its probes and light layers (--light-layers: the bundle keeps them),
# then (1) frames of 16 ms after one lamp's intensity doubled, with probes refreshed in them and
# without (the same bundle without probes.bin's grid in its manifest): frame times, probe sets per
# frame; (2) bench_edit_cost on the bundle with probes and with light layers, after 0, 16 and 256
# samples (what an edit costs with the probes' read-back, and whether the scaling's cost depends on
# the samples refreshed before). Writes $OUT/summary.txt.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/probe_refresh.txz
R=$W/runtime/bin/exitance-relight
export LD_LIBRARY_PATH=$W/runtime/lib
S=$OUT/summary.txt
$R --list-devices > $S
$R $W/building.bake -o $W/lit.bake --spp 1024 --seed 7 --light-layers --no-frame-errors --json > $W/lit.json
python3 -c "import json; r=json.load(open('$W/lit.json')); print('lit', r['spp'], 'spp', {k: round(v, 3) for k, v in r['seconds'].items() if isinstance(v, float)}, r['bundle_light_layers'])" >> $S
# The same bundle without probes: its manifest's probes block dropped.
cp -r $W/lit.bake $W/noprobes.bake
python3 -c "import json; p='$W/noprobes.bake/manifest.json'; m=json.load(open(p)); m.pop('probes'); json.dump(m, open(p, 'w'))"
for b in lit noprobes; do
  $R $W/$b.bake -o $W/${b}_out.bake --edits $W/double.json --frames ${FRAMES:-30} --budget-ms 16 --seed 3 --no-frame-errors --json > $W/${b}_frames.json
  python3 -c "
import json; r=json.load(open('$W/${b}_frames.json')); fr=r['frames']; ms=sorted(f['milliseconds'] for f in fr)
print('$b', 'edits_s %.5f'%r['seconds']['edits'], 'scaled', r['edits'].get('scaled_light_layers'), 'frames', len(fr), 'frame_ms median %.2f p95 %.2f max %.2f'%(ms[len(ms)//2], ms[int(0.95*(len(ms)-1))], ms[-1]), 'over 17 ms', sum(m > 17 for m in ms), 'spp', r['spp'])
print('  probes per frame', [f.get('probes', {}).get('refreshed', 0) for f in fr])
print('  probe samples', [f.get('probes', {}).get('samples', 0) for f in fr][-1], 'texel samples per frame', [f['samples_added'] for f in fr])" >> $S
done
for before in 0 16 256; do
  echo "bench_edit_cost double, probes and light layers, after $before samples:" >> $S
  $W/bench_edit_cost $W/lit.bake --edits $W/double.json --edits-back $W/double_back.json --repeat 9 --samples-before $before >> $S
done
echo "bench_edit_cost double, no probes, after 0 samples:" >> $S
$W/bench_edit_cost $W/noprobes.bake --edits $W/double.json --edits-back $W/double_back.json --repeat 9 --samples-before 0 >> $S
cat $S
