#!/usr/bin/env python3
"""Writes a textured variant of a glTF scene for benchmarks (no dependencies).

Every non-emissive material gets a base-colour texture: a 64x64 sRGB checker of two greys
(embedded PNG data URI), read through TEXCOORD_0 with a KHR_texture_transform scale of 8 (REPEAT
wrap), so each triangle's albedo varies per point and the kernels take the textured path. The
mean albedo changes by the checker's mean factor; geometry, lights and lightmap UVs stay.
Buffers referenced by relative URIs are resolved against the input's folder (the output is
written beside it). With --flat the texture is uniformly white (sRGB 255 = 1.0): the albedo and
so every path stay those of the input, and only the texture lookups are added (the cost of the
textured path, measured alone).

  bench/make_textured_variant.py [--flat] IN.gltf OUT.gltf
"""
import base64
import json
import os
import struct
import sys
import zlib


def checker_png(size=64, cells=8, dark=90, light=220):
    rows = []
    for y in range(size):
        row = bytearray([0])  # filter: none
        for x in range(size):
            v = light if ((x * cells // size) + (y * cells // size)) % 2 == 0 else dark
            row += bytes([v, v, v])
        rows.append(bytes(row))
    raw = zlib.compress(b"".join(rows), 9)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0)  # 8-bit RGB
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", raw) + chunk(b"IEND", b"")


def main():
    args = sys.argv[1:]
    flat = "--flat" in args
    args = [a for a in args if a != "--flat"]
    if len(args) != 2:
        sys.exit(__doc__)
    source, target = args
    with open(source) as f:
        gltf = json.load(f)
    base = os.path.relpath(os.path.dirname(os.path.abspath(source)), os.path.dirname(os.path.abspath(target)))
    for b in gltf.get("buffers", []):
        uri = b.get("uri", "")
        if uri and not uri.startswith("data:") and base != ".":
            b["uri"] = os.path.join(base, uri)
    gltf.setdefault("images", []).append(
        {"uri": "data:image/png;base64," + base64.b64encode(checker_png(dark=255, light=255) if flat else checker_png()).decode()})
    gltf.setdefault("samplers", []).append({"wrapS": 10497, "wrapT": 10497})
    gltf.setdefault("textures", []).append({"source": len(gltf["images"]) - 1, "sampler": len(gltf["samplers"]) - 1})
    texture = len(gltf["textures"]) - 1
    textured = 0
    for m in gltf.get("materials", []):
        if any(c > 0 for c in m.get("emissiveFactor", [0, 0, 0])):
            continue
        pbr = m.setdefault("pbrMetallicRoughness", {})
        pbr["baseColorTexture"] = {"index": texture, "texCoord": 0,
                                   "extensions": {"KHR_texture_transform": {"scale": [8, 8]}}}
        textured += 1
    used = gltf.setdefault("extensionsUsed", [])
    if "KHR_texture_transform" not in used:
        used.append("KHR_texture_transform")
    with open(target, "w") as f:
        json.dump(gltf, f)
    print(f"{target}: {textured} of {len(gltf.get('materials', []))} materials textured")


if __name__ == "__main__":
    main()
