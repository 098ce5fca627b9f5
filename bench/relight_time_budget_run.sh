#!/bin/bash
# exitance-relight --time T on the GPU machine: lighting seconds against the budget (issue 15).
# Payload: bench/guiding_gpu_pack.sh (its .replay/gd.txz); carry .gl and .replay; copy this script to
# .replay/ and run `bash .replay/relight_time_budget_run.sh` there.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xJf .replay/gd.txz
R=/tmp/w/rt/bin/exitance-relight
field() { grep -o "\"$1\": *[0-9.e+-]*" $2 | head -1 | sed 's/.*: *//'; }
for scene in ajar cornell courtyard; do
  $R /tmp/w/$scene.bake -o /tmp/w/warm.bake --spp 4 --seed 1 --json > /dev/null
  for t in 0.1 0.25 1 2; do
    for rep in 1 2; do
      $R /tmp/w/$scene.bake -o /tmp/w/o.bake --spp 0 --time $t --seed $rep --json > /tmp/w/r.json
      echo "$scene --time $t rep $rep: lighting $(field lighting_seconds /tmp/w/r.json) s, rays $(field rays /tmp/w/r.json)"
    done
  done
done
