#!/bin/bash
# On the GPU machine (carry .gl and .replay; .replay/relight.txz from bench/relight_assets_pack.sh):
# re-lights each named bundle REPS times at SPP samples per texel and prints the report's figures.
#   bash .replay/relight_assets_gpu_run.sh SPP REPS BUNDLE...
set -e
spp=$1; reps=$2; shift 2
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xJf .replay/relight.txz
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R=/tmp/w/runtime/bin/exitance-relight
for rep in $(seq 1 $reps); do
  for b in "$@"; do
    $R /tmp/w/$b.bake -o /tmp/w/out-$b.bake --spp $spp --seed 1 --json > /tmp/w/r.json 2>>/tmp/w/err.log || { cat /tmp/w/err.log; exit 1; }
    printf "%s rep %s: " $b $rep; grep -E '"(lighting_seconds|rays|rays_per_second|estimated_relative_mse|nonfinite_samples)"' /tmp/w/r.json | tr -d '\n '; echo
  done
done
