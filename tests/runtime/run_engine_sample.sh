#!/usr/bin/env bash
# run_engine_sample.sh BAKE ENGINE_SAMPLE EXITANCE_VIEW SAMPLE_DIR: the Cornell room with a point light
# "Lamp" added, baked small on the CPU; samples/engine_sample draws 3 frames on its own Vulkan device
# (validation layer on) while the lamp moves from left to right. Checks: exit status 0 and no
# validation error; frame 0 (the baked lightmap, nothing edited) matches exitance-view's drawing of
# the same bundle from the same camera; the last frame is lit differently, brighter on the right.
set -euo pipefail
bake="$1" sample="$2" view="$3" samples="$4"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT

# The loader skips a layer named in VK_INSTANCE_LAYERS that it cannot find, silently: make sure the
# validation layer is installed, or the run below would check nothing.
found=""
for folder in ${VK_LAYER_PATH:+${VK_LAYER_PATH//:/ }} ${VK_ADD_LAYER_PATH:+${VK_ADD_LAYER_PATH//:/ }} \
              /usr/local/share/vulkan/explicit_layer.d /usr/share/vulkan/explicit_layer.d \
              /etc/vulkan/explicit_layer.d; do
  if [ -f "$folder/VkLayer_khronos_validation.json" ]; then found="$folder"; fi
done
if [ -z "$found" ]; then
  echo "VkLayer_khronos_validation.json not found: install the Vulkan validation layers" >&2
  exit 1
fi

# The Cornell room has only an emissive ceiling panel: add a point light on its own root node (so its
# node's translation is its position), and dim the panel so that the lamp dominates.
cp "$samples/cornell_room.bin" "$dir/"
python3 - "$samples/cornell_room.gltf" "$dir/room.gltf" <<'PY'
import json, sys
gltf = json.load(open(sys.argv[1]))
gltf.setdefault('extensionsUsed', []).append('KHR_lights_punctual')
gltf.setdefault('extensions', {})['KHR_lights_punctual'] = {
    'lights': [{'name': 'Lamp', 'type': 'point', 'color': [1.0, 0.95, 0.9], 'intensity': 12.0}]}
gltf['nodes'].append({'name': 'LampNode', 'translation': [-1.2, 2.8, 0.4],
                      'extensions': {'KHR_lights_punctual': {'light': 0}}})
gltf['scenes'][gltf.get('scene', 0)]['nodes'].append(len(gltf['nodes']) - 1)
for m in gltf['materials']:
    if m['name'] == 'CeilingLight':
        m['extensions']['KHR_materials_emissive_strength']['emissiveStrength'] = 4.0
json.dump(gltf, open(sys.argv[2], 'w'))
PY
# 16 samples per texel: the least for which the runtime starts from (and publishes) the baked lightmap
# (refresh/baked_lightmap.h kBakedStartMinimumSamples).
"$bake" "$dir/room.gltf" -o "$dir/room.bake" --backend cpu --spp 16 --texel-density 4 --probe-spp 16 2>/dev/null

camera=(--look-from 0,2,1.9 --look-at 0,1.6,-2 --yfov 1.2 --size 160,120)
status=0
VK_INSTANCE_LAYERS="${VK_INSTANCE_LAYERS:-VK_LAYER_KHRONOS_validation}" \
  "$sample" "$dir/room.gltf" "$dir/room.bake" Lamp -1.2,2.8,0.4 1.2,2.8,0.4 "${camera[@]}" --frames 3 \
  -o "$dir/strip.png" 2>"$dir/stderr.txt" || status=$?
cat "$dir/stderr.txt" >&2
test "$status" -eq 0 || { echo "exitance_engine_sample exited with $status" >&2; exit 1; }
if grep -qi "vulkan error\|validation error" "$dir/stderr.txt"; then echo "validation errors (above)" >&2; exit 1; fi
"$view" "$dir/room.bake" "${camera[@]}" -o "$dir/view.png" 2>/dev/null

python3 - "$dir/strip.png" "$dir/view.png" <<'PY'
import struct, sys, zlib

def read_png(path):
    """8-bit RGB PNGs as stb_image_write writes them (any row filter): (width, height, rows of bytes)."""
    data = open(path, 'rb').read()
    assert data[:8] == b'\x89PNG\r\n\x1a\n', path
    at, idat = 8, b''
    while at < len(data):
        length, kind = struct.unpack('>I4s', data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if kind == b'IHDR':
            width, height, depth, colour = struct.unpack('>IIBB', body[:10])
            assert (depth, colour) == (8, 2), (path, depth, colour)
        elif kind == b'IDAT':
            idat += body
        at += 12 + length
    raw, stride, bpp = zlib.decompress(idat), width * 3, 3
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = previous[i], previous[i - bpp] if i >= bpp else 0
            if kind == 1: line[i] = (line[i] + a) & 255
            elif kind == 2: line[i] = (line[i] + b) & 255
            elif kind == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        previous = line
    return width, height, rows

strip_width, height, strip = read_png(sys.argv[1])
width, view_height, view = read_png(sys.argv[2])
assert strip_width == 3 * width and view_height == height, (strip_width, height, width, view_height)
def frame(f):
    return [[tuple(strip[y][(f * width + x) * 3:(f * width + x) * 3 + 3]) for x in range(width)] for y in range(height)]
first, last = frame(0), frame(2)
reference = [[tuple(view[y][x * 3:x * 3 + 3]) for x in range(width)] for y in range(height)]
pixels = width * height

# (a) Frame 0 draws what exitance-view ray-casts from the same bundle: the same camera, the same
# bilinear lookup between texel centres, the same tone curve. What may differ: a pixel whose centre
# lies within rounding of a triangle edge (rasterized vs ray-cast coverage), and the device's filter
# weights (8 fractional bits on most GPUs and lavapipe) against the loader's float weights, at most a
# few 8-bit steps where neighbouring texels differ much (the room's noisy 16-sample texels).
close = sum(1 for y in range(height) for x in range(width)
            if max(abs(a - b) for a, b in zip(first[y][x], reference[y][x])) <= 6)
print(f"frame 0 against exitance-view: {close / pixels:.4f} of the pixels within 6/255 per channel")
assert close >= 0.97 * pixels, close / pixels

# (b) The lamp moved from x = -1.2 to 1.2: pixels change, the right third gets brighter on average.
changed = sum(1 for y in range(height) for x in range(width)
              if max(abs(a - b) for a, b in zip(first[y][x], last[y][x])) > 10)
def mean(image, x0, x1):
    return sum(sum(image[y][x]) for y in range(height) for x in range(x0, x1)) / (3 * height * (x1 - x0))
left = (mean(first, 0, width // 3), mean(last, 0, width // 3))
right = (mean(first, 2 * width // 3, width), mean(last, 2 * width // 3, width))
print(f"last frame against frame 0: {changed / pixels:.4f} of the pixels changed by more than 10/255; "
      f"mean of the left third {left[0]:.1f} -> {left[1]:.1f}, right third {right[0]:.1f} -> {right[1]:.1f}")
assert changed > 0.01 * pixels, changed / pixels
assert right[1] > right[0] + 2 and left[1] < left[0] - 2, (left, right)
PY
