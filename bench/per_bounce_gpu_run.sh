#!/bin/bash
# On the GPU machine (carry .gl and .replay; .replay/pb.txz holds a runtime folder `rt` from
# `cmake --install BUILD --component runtime`, with build/bench/bench_bundle_rel_mse copied into rt/bin,
# and cornell.bake, building.bake, city.bake: manifest, probes.bin, scene.bin, svo.bin of CPU bakes).
# Per scene: a two-seed 4096-spp path-traced reference, then path at 64/256/1024 spp and the
# per-bounce mode at 16/64/256 spp, timed, and each one's relMSE against the reference. With
# Each per-bounce line ends with the host loop's `bounces.seconds` (passes, caches, tail, assembly).
# CACHES="device host" the per-bounce runs are repeated with their layer caches built on the host
# (exitance-relight --bounce-caches host, the earlier path; the same results bit for bit): the A/B of
# building them on the device (docs/lighting-core.md "Per-bounce mode").
# STAGES=1 adds one 64-spp per-bounce run with --stage-statistics per scene: each wavefront stage's
# GPU seconds beside the run's lighting seconds (the rest is host work and idle device).
# DENOISE=1 adds the per-bounce mode at 16/64/256 spp and path tracing at 64/256 spp with --denoise
# (the device's texture-space filter; its `relight.denoise.seconds` printed beside the lighting).
#   bash .replay/per_bounce_gpu_run.sh        (env SCENES, CACHES, STAGES, DENOISE)
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xJf .replay/pb.txz
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R=/tmp/w/rt/bin/exitance-relight
field() { grep -o "\"$1\": *[0-9.e+-]*" $2 | head -1 | sed 's/.*: *//'; }
for scene in ${SCENES:-cornell building city}; do
  B=/tmp/w/$scene.bake
  $R $B -o /tmp/w/warm.bake --spp 4 --seed 1 --json > /dev/null
  $R $B -o /tmp/w/warm.bake --spp 4 --seed 1 --integrator bounces --json > /dev/null
  $R $B -o /tmp/w/$scene-refA.bake --spp 4096 --seed 101 --json > /tmp/w/refA.json
  $R $B -o /tmp/w/$scene-refB.bake --spp 4096 --seed 202 --json > /tmp/w/refB.json
  tests=""
  for spp in 64 256 1024; do
    $R $B -o /tmp/w/$scene-path$spp.bake --spp $spp --seed 1 --json > /tmp/w/r.json
    echo "$scene path $spp spp: lighting $(field lighting_seconds /tmp/w/r.json) s, rays $(field rays /tmp/w/r.json)"
    tests="$tests /tmp/w/$scene-path$spp.bake"
  done
  for caches in ${CACHES:-device}; do
    for spp in 16 64 256; do
      $R $B -o /tmp/w/$scene-bounces$spp-$caches.bake --spp $spp --seed 1 --integrator bounces --bounce-caches $caches \
        --json > /tmp/w/r.json
      echo "$scene bounces ($caches caches) $spp spp: lighting $(field lighting_seconds /tmp/w/r.json) s, rays $(field rays /tmp/w/r.json)," \
        "host loop $(python3 -c "import json; b=json.load(open('/tmp/w/r.json')).get('bounces', {}); s=b.get('seconds', {}); print(' '.join('%s %.3f' % kv for kv in sorted(s.items())), '; layers', len(b.get('samples_per_layer', [])))")"
      tests="$tests /tmp/w/$scene-bounces$spp-$caches.bake"
    done
  done
  if [ -n "${DENOISE:-}" ]; then
    denoised() { python3 -c "import json; r=json.load(open('/tmp/w/r.json')); d=r.get('denoise') or r.get('relight', {}).get('denoise') or r.get('stats', {}).get('relight', {}).get('denoise', {}); print('%.3f' % d.get('seconds', -1))"; }
    for spp in 64 256; do
      $R $B -o /tmp/w/$scene-path$spp-denoise.bake --spp $spp --seed 1 --denoise --json > /tmp/w/r.json
      echo "$scene path --denoise $spp spp: lighting $(field lighting_seconds /tmp/w/r.json) s, filter $(denoised) s"
      tests="$tests /tmp/w/$scene-path$spp-denoise.bake"
    done
    for spp in 16 64 256; do
      $R $B -o /tmp/w/$scene-bounces$spp-denoise.bake --spp $spp --seed 1 --integrator bounces --denoise --json > /tmp/w/r.json
      echo "$scene bounces --denoise $spp spp: lighting $(field lighting_seconds /tmp/w/r.json) s, filter $(denoised) s"
      tests="$tests /tmp/w/$scene-bounces$spp-denoise.bake"
    done
  fi
  if [ -n "${STAGES:-}" ]; then
    $R $B -o /tmp/w/stages.bake --spp 64 --seed 1 --integrator bounces --stage-statistics --json > /tmp/w/r.json
    python3 -c "
import json; r=json.load(open('/tmp/w/r.json')); g=sum(s['gpu_seconds'] for s in r['stages'])
print('$scene bounces 64 spp, stages: lighting %.3f s, GPU stages %.3f s'%(r['lighting_seconds'], g))
for s in r['stages']: print('  %-12s %.4f s  rays %.3g  lanes %.2f'%(s['stage'], s['gpu_seconds'], s['rays'], s['lane_efficiency']))"
  fi
  echo "$scene reference: $(field lighting_seconds /tmp/w/refA.json) s per 4096-spp run"
  LD_LIBRARY_PATH=/tmp/w/rt/lib /tmp/w/rt/bin/bench_bundle_rel_mse /tmp/w/$scene-refA.bake /tmp/w/$scene-refB.bake $tests | sed "s#/tmp/w/##"
  rm -rf /tmp/w/$scene-*.bake
done
