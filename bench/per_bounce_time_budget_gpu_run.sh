#!/bin/bash
# Packed here: cmake --install BUILD --component runtime --prefix rt (after) and rtOld (before: main
# before the partial last pass), building.bake and city.bake as in bench/results/open-city-gpu.md, all
# in .replay/budget.txz; run there with carry [".gl", ".replay"].
# On the GPU machine: exitance-relight --time with the per-bounce mode, before (rtOld) and after (rt)
# the partial last layer pass; path mode for reference.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xJf .replay/budget.txz
for s in building city; do /tmp/w/rt/bin/exitance-relight /tmp/w/$s.bake -o /tmp/w/warm.bake --spp 16 --seed 1 --integrator bounces --json > /dev/null; done
for s in building city; do for T in 0.25 1 4; do for v in rtOld rt; do
  /tmp/w/$v/bin/exitance-relight /tmp/w/$s.bake -o /tmp/w/o.bake --spp 0 --time $T --seed 1 --integrator bounces --json > /tmp/w/r.json 2>/tmp/w/r.err || { echo "$s $T $v failed"; tail -2 /tmp/w/r.err; continue; }
  printf "%s bounces --time %s %s: " $s $T $v; grep -E '"(lighting_seconds|spp)"' /tmp/w/r.json | tr -d '\n '; echo
done; done; done
for s in building city; do for v in rtOld rt; do
  /tmp/w/$v/bin/exitance-relight /tmp/w/$s.bake -o /tmp/w/o.bake --spp 0 --time 1 --seed 1 --integrator path --json > /tmp/w/r.json
  printf "%s path --time 1 %s: " $s $v; grep -E '"(lighting_seconds|spp)"' /tmp/w/r.json | tr -d '\n '; echo
done; done
