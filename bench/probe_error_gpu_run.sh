#!/bin/bash
# Runs on the GPU machine (bench/probe_refresh_gpu_pack.sh packs what it needs): how far the
# refreshed probes are from the edited scene's, frame by frame (bench/results/probe-refresh.md). The
# building at 12 texels/m lit to 1024 spp with light layers; per edit (EDITS: double, a lamp's
# intensity doubled, scaled with 0 rays; move, the lamp moved and brighter, a restart), the
# references: two whole runs of the edited scene's probes at REF_PROBE_SPP (16384) samples each
# (seeds 101 and 202); then a session that refreshes WARM (32) samples per texel in 16 ms frames
# before the edit (its probes with it), the edit and FRAMES (1 6 30) frames of 16 ms, each writing
# what its probes show. bench_probe_rel_mse gives each one's relMSE of irradiance against the
# references, the lit bundle's own probes (what was shown before the edit) as "unrefreshed"; the
# frames' JSON gives the probes' own estimated error and how many show their refreshed estimate.
# FRAME_ERRORS: "--no-frame-errors" leaves the per-frame read-backs out (the frames' timing then
# has no idle gaps; the probes' own estimates are not reported). Also two references of the scene
# before the edit, for the figure over the probes the edit changed (bench_probe_rel_mse --changed).
# Then bench_edit_cost for the scaling edit after 256 samples (probes scaled too).
# BEFORE: with .replay/probe_refresh_before.txz (another runtime folder, packed by
# bench/probe_refresh_gpu_pack.sh's BEFORE_RUNTIME), its frames too, as t_before_*.
# Writes $OUT/summary.txt.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/probe_refresh.txz
R=$W/runtime/bin/exitance-relight
export LD_LIBRARY_PATH=$W/runtime/lib
runtimes="runtime"
if [ -f .replay/probe_refresh_before.txz ]; then
  mkdir -p $W/before && tar -C $W/before -xJf .replay/probe_refresh_before.txz
  runtimes="runtime before"
fi
S=$OUT/summary.txt
$R --list-devices > $S
$R $W/building.bake -o $W/lit.bake --spp 1024 --seed 7 --light-layers --no-frame-errors --json > $W/lit.json
# The scene before the edits: two references the same way (bench_probe_rel_mse --changed).
for seed in 101 202; do
  rm -rf $W/src.bake && cp -r $W/lit.bake $W/src.bake
  python3 -c "import json; p='$W/src.bake/manifest.json'; m=json.load(open(p)); m['settings']['probe_spp']=${REF_PROBE_SPP:-16384}; json.dump(m, open(p, 'w'))"
  $R $W/src.bake -o $W/ref_before_$seed.bake --spp 1 --seed $seed --no-frame-errors --json > $W/ref_before_$seed.json
done
for e in ${EDITS:-double move}; do
  for seed in 101 202; do
    rm -rf $W/src.bake && cp -r $W/lit.bake $W/src.bake
    python3 -c "import json; p='$W/src.bake/manifest.json'; m=json.load(open(p)); m['settings']['probe_spp']=${REF_PROBE_SPP:-16384}; json.dump(m, open(p, 'w'))"
    $R $W/src.bake -o $W/ref_${e}_$seed.bake --edits $W/$e.json --spp 1 --seed $seed --no-frame-errors --json > $W/ref_${e}_$seed.json
  done
  tests="$W/lit.bake"
  for rt in $runtimes; do
  t=t; [ $rt = runtime ] || t=t_$rt
  for n in ${FRAMES:-1 6 30}; do
    LD_LIBRARY_PATH=$W/$rt/lib $W/$rt/bin/exitance-relight $W/lit.bake -o $W/${t}_${e}_$n.bake --spp-before-edits ${WARM:-32} --edits $W/$e.json --frames $n --budget-ms 16 --seed 3 $FRAME_ERRORS --json > $W/${t}_${e}_$n.json
    tests="$tests $W/${t}_${e}_$n.bake"
    python3 -c "
import json; r=json.load(open('$W/${t}_${e}_$n.json')); fr=r['frames']
print('$rt $e', $n, 'frames: edits_ms %.3f'%(r['seconds']['edits']*1e3), 'scaled', r['edits'].get('scaled_light_layers'), 'samples_before', r['edits'].get('samples_before'), 'probes_written', r.get('probes_written'))
print('  per frame ms', [round(f['milliseconds'], 1) for f in fr])
print('  probes refreshed per frame', [f.get('probes', {}).get('refreshed', 0) for f in fr])
print('  probes showing refreshed', [f.get('probes', {}).get('showing_refreshed') for f in fr])
print('  probes estimated relMSE', [f.get('probes', {}).get('estimated_relative_mse') for f in fr])
print('  probe samples', [f.get('probes', {}).get('samples') for f in fr])" >> $S
  done
  done
  echo "$e: bench_probe_rel_mse (first: the lit bundle's probes, unrefreshed)" >> $S
  $W/bench_probe_rel_mse --changed $W/ref_before_101.bake $W/ref_before_202.bake $W/ref_${e}_101.bake $W/ref_${e}_202.bake $tests | sed "s#$W/##" >> $S
done
# The same 30 frames after each edit without the per-frame read-backs: the frames' timing and
# probe batches as an engine's session has them.
for e in ${EDITS:-double move}; do
  nts=""
  for rt in $runtimes; do
  LD_LIBRARY_PATH=$W/$rt/lib $W/$rt/bin/exitance-relight $W/lit.bake -o $W/nt_${rt}_$e.bake --spp-before-edits ${WARM:-32} --edits $W/$e.json --frames 30 --budget-ms 16 --seed 3 --no-frame-errors --json > $W/nt_${rt}_$e.json
  nts="$nts $W/nt_${rt}_$e.bake"
  python3 -c "
import json; r=json.load(open('$W/nt_${rt}_$e.json')); fr=r['frames']; ms=sorted(f['milliseconds'] for f in fr)
print('$rt $e, 30 frames, --no-frame-errors: frame_ms median %.2f p95 %.2f max %.2f'%(ms[len(ms)//2], ms[int(0.95*(len(ms)-1))], ms[-1]), 'over 17 ms', sum(m > 17 for m in ms))
print('  probes refreshed per frame', [f.get('probes', {}).get('refreshed', 0) for f in fr])" >> $S
  done
  echo "$e, 30 frames without read-backs: bench_probe_rel_mse" >> $S
  $W/bench_probe_rel_mse --changed $W/ref_before_101.bake $W/ref_before_202.bake $W/ref_${e}_101.bake $W/ref_${e}_202.bake $W/lit.bake $nts | sed "s#$W/##" >> $S
done
echo "bench_edit_cost double, probes and light layers, after 256 samples:" >> $S
$W/bench_edit_cost $W/lit.bake --edits $W/double.json --edits-back $W/double_back.json --repeat 9 --samples-before 256 >> $S
cat $S
