#!/bin/bash
# Runs on the GPU machine: refresh frames on the building without per-frame read-backs (frame times
# only), unedited and after a light move; then one run with per-frame errors for comparison.
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xzf .replay/refresh.tgz
R=/tmp/w/runtime/bin/exitance-relight
$R /tmp/w/building.bake -o /tmp/w/a.bake --spp 4096 --frames 60 --budget-ms 16 --seed 1 --no-frame-errors --json > $OUT/frames_unedited_fitted.json
$R /tmp/w/building.bake -o /tmp/w/b.bake --edits /tmp/w/move_light.json --spp 4096 --frames 60 --budget-ms 16 --seed 1 --no-frame-errors --json > $OUT/frames_light_moved_fitted.json
python3 - <<'PY'
import json,os
for n in ['frames_unedited_fitted','frames_light_moved_fitted']:
  r=json.load(open(os.environ['OUT']+'/'+n+'.json'))
  ms=[f['milliseconds'] for f in r['frames']]
  print(n, 'frames', len(ms), 'over 16 ms:', sum(1 for m in ms if m>16), 'max %.1f'%max(ms), 'spp at end', r['frames'][-1]['samples_per_texel'], 'total ms %.1f'%sum(ms), 'relMSE', r['estimated_relative_mse'])
  print('  ', ' '.join('%.1f/%d'%(f['milliseconds'],f['samples_added']) for f in r['frames']))
PY
