#!/usr/bin/env bash
# run_refresh_demo.sh BAKE DEMO SAMPLE_DIR: bakes the Cornell room small, runs the refresh demo over
# 3 frames (the tall box moving), and checks the strip image: a binary PPM of 3 page widths whose
# frames differ (the box's footprint on the floor moved), and the written bundle's manifest.
set -euo pipefail
bake="$1" demo="$2" samples="$3"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
"$bake" "$samples/cornell_room.gltf" -o "$dir/cornell.bake" --backend cpu --spp 1 --texel-density 4 --probe-spp 16 2>/dev/null
"$demo" "$dir/cornell.bake" TallBox -0.7,0,-0.6 -0.2,0,0.4 "$dir/strip.ppm" 3 4
python3 - "$dir/strip.ppm" <<'PY'
import sys
data = open(sys.argv[1], 'rb').read()
magic, size, maxval, pixels = data.split(b'\n', 3)
width, height = map(int, size.split())
assert magic == b'P6' and maxval == b'255', (magic, maxval)
assert len(pixels) == width * height * 3, (len(pixels), width, height)
assert width % 3 == 0
frame = width // 3
def crop(f):
    return bytes(b for y in range(height) for b in pixels[(y * width + f * frame) * 3:(y * width + (f + 1) * frame) * 3])
first, last = crop(0), crop(2)
changed = sum(1 for a, b in zip(first, last) if abs(a - b) > 40)
assert changed > 30, changed   # the footprint moved
print("strip", width, "x", height, "bytes changed between the first and last frame:", changed)
PY
test -f "$dir/strip.ppm.bake/manifest.json"
