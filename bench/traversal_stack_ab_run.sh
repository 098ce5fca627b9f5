#!/bin/bash
# On the GPU machine: A/B/C of three runtime folders (rtA, rtB, rtC in .replay/ab.txz, each from
# `cmake --install BUILD --component runtime --prefix rtX` of one variant, with building.bake and
# city.bake packed as bench/open_city_gpu_pack.sh packs the city), alternated, 256 spp.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xJf .replay/ab.txz
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for scene in building city; do
  for v in A B C; do /tmp/w/rt$v/bin/exitance-relight /tmp/w/$scene.bake -o /tmp/w/warm.bake --spp 16 --seed 1 --json > /dev/null; done
  for rep in 1 2 3; do
    for v in A B C; do
      /tmp/w/rt$v/bin/exitance-relight /tmp/w/$scene.bake -o /tmp/w/out$v.bake --spp 256 --seed 1 --json > /tmp/w/$scene$v$rep.json
      printf "%s %s rep %s: " $scene $v $rep; grep -E '"(lighting_seconds|rays_per_second)"' /tmp/w/$scene$v$rep.json | tr -d '\n '; echo
    done
  done
  md5sum /tmp/w/out?.bake/*.exr | sed 's#/tmp/w/##'
  for v in A B C; do
    /tmp/w/rt$v/bin/exitance-relight /tmp/w/$scene.bake -o /tmp/w/s.bake --spp 256 --seed 1 --stage-statistics --json > /tmp/w/s$scene$v.json 2>/tmp/w/s$scene$v.err || true
    echo "== $scene $v stages"; grep -E "extend|connect|shade" /tmp/w/s$scene$v.err | head -6
  done
done
[ -n "$OUT" ] && cp /tmp/w/*.json "$OUT"/ || true
