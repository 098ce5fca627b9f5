#!/bin/bash
# On the GPU machine (device tool, carry [".gl", ".replay"]): traversal-only rays/s and a 64-spp
# frame after a 1 mm nudge of one instance, two runtime folders A/B: the refit that widened every split
# fragment (rtP) against the one that keeps unmoved leaves' boxes (rtR). Packed here
# (.replay/share.txz): the building and city bundles of bench/results/open-city-gpu.md, the two
# `cmake --install BUILD --component runtime` folders, and nudge-building.json
# ({"edits": [{"node": "Room_0_0_0", "translation": [0, 0.001, 0]}]}) and nudge-city.json
# ({"edits": [{"node": "Tower_0_1", "translation": [-90.0, 0.001, -126.0]}]}).
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/share.txz
field() { grep -oE "\"$1\": [0-9.e+-]+" $W/r.json | head -1 | sed 's/.*: //'; }
for round in 1 2 3; do for s in building city; do for e in none nudge; do for v in rtP rtR; do
  E=""; [ $e = nudge ] && E="--edits $W/nudge-$s.json"
  rm -rf $W/o.bake
  $W/$v/bin/exitance-relight $W/$s.bake -o $W/o.bake $E --frames 1 --spp 64 --no-frame-errors --traversal-rays 67108864 --json > $W/r.json
  echo "$v $s $e: traversal_only $(field traversal_only_rays_per_second) lighting_s $(field lighting_seconds) rays_per_s $(field rays_per_second) md5 $(md5sum < $W/o.bake/lightmap-0.exr | cut -c1-8)"
done; done; done; done
