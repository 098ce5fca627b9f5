#!/bin/bash
# Issue 32's lavapipe goal, on this machine (no GPU): the building at 1 texel/m baked on the CPU by
# path tracing at 1024 spp, one point light moved and brightened (bench/refresh_move_light.json), then
# refreshed by exitance-relight on lavapipe in 100 ms frames (1, 2 and 5 frames, each its own run);
# each output's per-texel relMSE against two 4096-spp CPU bakes of the edited glTF (seeds 101 and
# 202, the edit applied to the glTF's JSON), the unrefreshed bundle's too.
# Usage: bash bench/refresh_lavapipe_run.sh [BUILD_DIR] [WORK_DIR]   (about 6 min on 2 cores)
# Writes WORK_DIR/summary.txt.
set -euo pipefail
B=${1:-build}; W=${2:-/tmp/refresh-lavapipe}
mkdir -p "$W"
S=$W/summary.txt
gltf=$B/samples/building.gltf
edits=bench/refresh_move_light.json
bake() { "$B/bake/bake" "$1" -o "$2" --backend cpu --integrator path --texel-density 1 --probes none --voxel-resolution none "${@:3}" > /dev/null 2>&1; }
[ -d "$W/base.bake" ] || bake "$gltf" "$W/base.bake" --spp 1024 --seed 7
# The edit applied to the glTF: the node's translation and its light's intensity, as the runtime
# applies them (docs/edits.md; the node is a root, its light placed once).
python3 - "$gltf" "$edits" "$W/edited.gltf" <<'PY'
import json, os, sys
gltf, edits, out = sys.argv[1:]
import shutil
g = json.load(open(gltf))
base = os.path.dirname(os.path.abspath(gltf))
for b in g.get('buffers', []) + g.get('images', []):  # the files it references, beside it (relative URIs)
    if 'uri' in b and not b['uri'].startswith('data:'):
        shutil.copy(os.path.join(base, b['uri']), os.path.join(os.path.dirname(out), b['uri']))
lights = g['extensions']['KHR_lights_punctual']['lights']
for e in json.load(open(edits))['edits']:
    if 'node' in e:
        node = next(n for n in g['nodes'] if n.get('name') == e['node'])
        node['translation'] = e['translation']
    if 'light' in e:
        light = next(l for l in lights if l.get('name') == e['light'])
        for k in ('intensity', 'color'):
            if k in e: light[k] = e[k]
json.dump(g, open(out, 'w'))
PY
for s in 101 202; do [ -d "$W/ref_$s.bake" ] || bake "$W/edited.gltf" "$W/ref_$s.bake" --spp 4096 --seed $s; done
: > "$S"
list=""
for f in 1 2 5; do
  "$B/runtime/exitance-relight" "$W/base.bake" -o "$W/frames_$f.bake" --edits "$edits" --frames $f --budget-ms 100 \
      --spp 4096 --seed 3 --json > "$W/frames_$f.json"
  python3 -c "
import json; r=json.load(open('$W/frames_$f.json')); ms=[x['milliseconds'] for x in r['frames']]
print('frames $f', r['device'], 'edits_s %.4f'%r['seconds']['edits'], 'changed_lights', r['edits']['changed_lights'], 'frame_ms', [round(m,1) for m in ms], 'spp', r['spp'])" >> "$S"
  list="$list $W/frames_$f.bake"
done
echo "relMSE (unrefreshed = base.bake, then 1, 2, 5 frames of 100 ms):" >> "$S"
"$B/bench/bench_bundle_rel_mse" "$W/ref_101.bake" "$W/ref_202.bake" "$W/base.bake" $list >> "$S"
cat "$S"
