#!/bin/bash
# On the GPU machine (carry .gl and .replay; .replay/relight_ab.txz from bench/relight_ab_gpu_pack.sh):
# the two exitance-relight programs alternated REPS times on the packed bundle with the same ARGS,
# after one warm-up run of each (the driver's shader cache); per run the lighting seconds, rays per
# second, the whole call's wall seconds and, for the per-bounce mode, its host loop's parts; then
# whether the two wrote the same lightmap bytes.
#   ARGS="--spp 256 --integrator bounces" REPS=4 bash .replay/relight_ab_gpu_run.sh
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/relight_ab.txz
export LD_LIBRARY_PATH=$W/rt/lib
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; echo "host: $(nproc) hardware threads; ARGS: ${ARGS:---spp 256}"; }
program() { [ "$1" = before ] && echo $W/before || echo $W/rt/bin/exitance-relight; }
for v in after before; do $(program $v) $W/bundle.bake -o $W/warm.bake --seed 1 ${ARGS:---spp 256} --json > /dev/null; done
for rep in $(seq ${REPS:-4}); do
  for v in after before; do
    start=$(date +%s.%N)
    timeout 300 $(program $v) $W/bundle.bake -o $W/out-$v.bake --seed 1 ${ARGS:---spp 256} --json > $W/r.json
    end=$(date +%s.%N)
    python3 - $W/r.json $v $rep $start $end <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); b = r.get('bounces', {}).get('seconds', {})
print('%s rep %s: lighting %.3f s, %.3g rays/s, whole call %.3f s%s' % (sys.argv[2], sys.argv[3], r['lighting_seconds'],
      r['rays_per_second'], float(sys.argv[5]) - float(sys.argv[4]),
      (', host loop ' + ' '.join('%s %.3f' % kv for kv in sorted(b.items()))) if b else ''))
PY
  done
done
md5sum $W/out-after.bake/lightmap-*.exr $W/out-before.bake/lightmap-*.exr | sed "s|$W/||"
