#!/bin/bash
# On the GPU machine (carry .gl and .replay; .replay/city.txz from bench/open_city_gpu_pack.sh):
# three uninstrumented re-lights of the open city at 256 spp, then one with --stage-statistics.
#   bash .replay/open_city_gpu_run.sh
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xJf .replay/city.txz
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R=/tmp/w/runtime/bin/exitance-relight
for rep in 1 2 3; do
  $R /tmp/w/city.bake -o /tmp/w/out.bake --spp 256 --seed 1 --json > /tmp/w/r$rep.json
  printf "rep %s: " $rep; grep -E '"(lighting_seconds|rays|rays_per_second|nonfinite_samples)"' /tmp/w/r$rep.json | tr -d '\n '; echo
done
$R /tmp/w/city.bake -o /tmp/w/outs.bake --spp 256 --seed 1 --stage-statistics --json > /tmp/w/s.json 2>/tmp/w/s.err || cat /tmp/w/s.err
cat /tmp/w/s.err | tail -30
[ -n "$OUT" ] && cp /tmp/w/r1.json /tmp/w/s.json "$OUT"/
