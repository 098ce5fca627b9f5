#!/bin/bash
# Runs on the GPU machine: refresh frames on the building after a light move, with priorities.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xzf .replay/refresh.tgz
R=/tmp/w/runtime/bin/exitance-relight
$R /tmp/w/building.bake -o /tmp/w/b.bake --edits /tmp/w/move_light.json --spp 4096 --frames 40 --budget-ms 16 --seed 1 --json > $OUT/frames_light_moved_prioritized.json
$R /tmp/w/building.bake -o /tmp/w/c.bake --edits /tmp/w/move_light.json --spp 256 --frames 8 --budget-ms 100 --seed 2 --json > $OUT/frames_light_moved_prioritized_100ms.json
python3 - <<'PY'
import json,os
for n in ['frames_light_moved_prioritized','frames_light_moved_prioritized_100ms']:
  r=json.load(open(os.environ['OUT']+'/'+n+'.json'))
  t=0
  print(n, r['device'], r['edits'], r.get('seconds'))
  for f in r['frames']:
    t+=f['milliseconds']
    print('  frame %2d %7.2f ms (cum %8.1f) spp %4d rays %d relMSE %s near %s: %s'%(f['frame'],f['milliseconds'],t,f['samples_per_texel'],f['rays'],f['estimated_relative_mse'],f.get('prioritized_texels'),f.get('prioritized_estimated_relative_mse')))
PY
