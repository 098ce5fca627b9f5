#!/bin/bash
# On the GPU machine (device tool, carry [".gl", ".replay"]): traversal-only rays/s and a 64-spp
# frame after moving one instance, two runtime folders A/B (bench/results/refresh-gpu.md: the refit
# that widened every split fragment, rtP; that keeps unmoved leaves' boxes, rtR; that also carries
# the moved triangles' fragments, rtS). Packed here (.replay/share.txz): the building and city
# bundles of bench/results/open-city-gpu.md, the two `cmake --install BUILD --component runtime`
# folders, and the edits
#   nudge-building.json {"edits": [{"node": "Room_0_0_0", "translation": [0, 0.001, 0]}]}
#   nudge-city.json     {"edits": [{"node": "Tower_0_1", "translation": [-90.0, 0.001, -126.0]}]}
#   turn-city.json      {"edits": [{"node": "Tower_0_1", "translation": [-90.0, 0.5, -126.0],
#                                   "rotation": [0, 0.2588190451, 0, 0.9659258263]}]}
#   bash bench/refit_nudge_gpu_run.sh A B [ROUNDS]
set -e
A=$1 B=$2 ROUNDS=${3:-2}
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/share.txz
field() { grep -oE "\"$1\": [0-9.e+-]+" $W/r.json | head -1 | sed 's/.*: //'; }
for round in $(seq $ROUNDS); do for s in city building; do for e in none nudge turn; do for v in $A $B; do
  E=""
  if [ $e != none ]; then [ -f $W/$e-$s.json ] || continue; E="--edits $W/$e-$s.json"; fi
  rm -rf $W/o.bake
  $W/$v/bin/exitance-relight $W/$s.bake -o $W/o.bake $E --frames 1 --spp 64 --no-frame-errors --traversal-rays 67108864 --json > $W/r.json
  echo "$v $s $e: traversal_only $(field traversal_only_rays_per_second) lighting_s $(field lighting_seconds) rays_per_s $(field rays_per_second) md5 $(md5sum < $W/o.bake/lightmap-0.exr | cut -c1-8)"
done; done; done; done
