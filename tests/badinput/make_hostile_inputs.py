#!/usr/bin/env python3
"""Generate the hostile glTF corpus for bake's bad-input tests (DESIGN.md §6 item 4).

Every file starts from one small, valid scene -- a unit cube with POSITION, NORMAL,
TEXCOORD_0 (glTF requires TEXCOORD_n to start at 0), TEXCOORD_1 (a non-overlapping 3x2
lightmap layout) and 16-bit indices -- and carries
exactly ONE defect, so the error bake reports can only be about that defect.

Writes tests/badinput/hostile/* and rewrites the `hostile` rows of
tests/badinput/expectations.tsv (rows of other corpora are kept as they are).
Deterministic: running it twice gives identical bytes.  Standard library only.

    python3 tests/badinput/make_hostile_inputs.py
"""
import base64
import copy
import json
import math
import os
import shutil
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "hostile")
TSV = os.path.join(HERE, "expectations.tsv")

FLOAT, USHORT, UINT, UBYTE, SHORT, BYTE = 5126, 5123, 5125, 5121, 5122, 5120
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963

# Accessor indices in the base scene (used in expected error substrings).
A_POS, A_NRM, A_UV1, A_IDX = 0, 1, 2, 3


# ----------------------------------------------------------------------------- base scene
def cube_geometry():
    """24 vertices (4 per face), 36 indices, lightmap UVs in a 3x2 grid of cells with margins."""
    faces = [  # normal, tangent u, tangent v
        ((1, 0, 0), (0, 0, -1), (0, 1, 0)),
        ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
        ((0, 1, 0), (1, 0, 0), (0, 0, -1)),
        ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
        ((0, 0, 1), (1, 0, 0), (0, 1, 0)),
        ((0, 0, -1), (-1, 0, 0), (0, 1, 0)),
    ]
    pos, nrm, uv, idx = [], [], [], []
    for f, (n, u, v) in enumerate(faces):
        cx, cy = f % 3, f // 3
        base = len(pos)
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            pos.append(tuple(0.5 * n[i] + 0.5 * su * u[i] + 0.5 * sv * v[i] for i in range(3)))
            nrm.append(tuple(float(c) for c in n))
            # cell is 1/3 x 1/2; keep a 1/16 margin inside each cell
            uv.append(((cx + 0.5 + 0.4375 * su) / 3.0, (cy + 0.5 - 0.4375 * sv) / 2.0))
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return pos, nrm, uv, idx


def pack(fmt, rows):
    return b"".join(struct.pack("<" + fmt, *(r if isinstance(r, (tuple, list)) else (r,))) for r in rows)


def pad4(b, fill=b"\0"):
    return b + fill * (-len(b) % 4)


class Scene:
    """A glTF document plus its single binary buffer, built view by view."""

    def __init__(self):
        self.bin = b""
        self.j = {
            "asset": {"version": "2.0", "generator": "exitance make_hostile_inputs.py"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0, "name": "Cube"}],
            "meshes": [],
            "materials": [{"name": "Grey", "pbrMetallicRoughness": {
                "baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0},
                "emissiveFactor": [0.5, 0.5, 0.5]}],
            "accessors": [],
            "bufferViews": [],
            "buffers": [],
        }

    def view(self, data, target=None, stride=None):
        self.bin = pad4(self.bin)
        bv = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if stride:
            bv["byteStride"] = stride
        if target:
            bv["target"] = target
        self.bin += data
        self.j["bufferViews"].append(bv)
        return len(self.j["bufferViews"]) - 1

    def accessor(self, rows, ctype, atype, target=None, minmax=False, normalized=False):
        fmt = {FLOAT: "f", USHORT: "H", UINT: "I", UBYTE: "B"}[ctype]
        n = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[atype]
        bv = self.view(pack(fmt * n, rows), target)
        acc = {"bufferView": bv, "componentType": ctype, "count": len(rows), "type": atype}
        if normalized:
            acc["normalized"] = True
        if minmax:
            cols = list(zip(*[r if isinstance(r, (tuple, list)) else (r,) for r in rows]))
            acc["min"] = [min(c) for c in cols]
            acc["max"] = [max(c) for c in cols]
        self.j["accessors"].append(acc)
        return len(self.j["accessors"]) - 1

    def finish_buffer(self, uri="data"):
        self.bin = pad4(self.bin)
        buf = {"byteLength": len(self.bin)}
        if uri == "data":
            buf["uri"] = "data:application/octet-stream;base64," + base64.b64encode(self.bin).decode()
        elif uri is not None:
            buf["uri"] = uri
        self.j["buffers"] = [buf]

    def gltf(self):
        return json.dumps(self.j, separators=(",", ":"), allow_nan=True).encode()


def cube(uv_sets=(0, 1), normals=True, idx_type=USHORT, mode=None, pos=None, nrm=None, uv=None,
         idx=None, uv_ctype=FLOAT):
    """The base scene; accessor order is POSITION, NORMAL, TEXCOORD_*, indices."""
    s = Scene()
    p0, n0, u0, i0 = cube_geometry()
    pos, nrm, uv, idx = pos or p0, nrm or n0, uv or u0, idx if idx is not None else i0
    attrs = {"POSITION": s.accessor(pos, FLOAT, "VEC3", ARRAY_BUFFER, minmax=True)}
    if normals:
        attrs["NORMAL"] = s.accessor(nrm, FLOAT, "VEC3", ARRAY_BUFFER)
    # The lightmap set comes first (accessor 2) so accessor numbers stay the same whether or
    # not a TEXCOORD_0 (the usual overlapping texture UVs) follows the indices.
    light = 1 if 1 in uv_sets else (0 if uv_sets else None)
    if light is not None:
        if uv_ctype == FLOAT:
            attrs["TEXCOORD_%d" % light] = s.accessor(uv, FLOAT, "VEC2", ARRAY_BUFFER)
        else:
            q = [(round(a * 65535), round(b * 65535)) for a, b in uv]
            attrs["TEXCOORD_%d" % light] = s.accessor(q, USHORT, "VEC2", ARRAY_BUFFER, normalized=True)
    prim = {"attributes": attrs, "material": 0}
    if idx is not False:
        prim["indices"] = s.accessor(idx, idx_type, "SCALAR", ELEMENT_ARRAY_BUFFER)
    if light == 1 and 0 in uv_sets:
        tex = [((i % 4) in (1, 2) and 1.0 or 0.0, (i % 4) in (0, 1) and 1.0 or 0.0) for i in range(len(pos))]
        attrs["TEXCOORD_0"] = s.accessor(tex, FLOAT, "VEC2", ARRAY_BUFFER)
    if mode is not None:
        prim["mode"] = mode
    s.j["meshes"].append({"name": "Cube", "primitives": [prim]})
    return s


def quad(mode, uv_sets=(0, 1)):
    """A unit quad in the XZ plane, 4 vertices, no indices, drawn with `mode`."""
    s = Scene()
    corners = [(-0.5, 0.0, -0.5), (0.5, 0.0, -0.5), (-0.5, 0.0, 0.5), (0.5, 0.0, 0.5)]
    uvs = [(0.05, 0.05), (0.95, 0.05), (0.05, 0.95), (0.95, 0.95)]
    if mode == 6:  # fan: around corner 0
        corners = [corners[0], corners[2], corners[3], corners[1]]
        uvs = [uvs[0], uvs[2], uvs[3], uvs[1]]
    attrs = {"POSITION": s.accessor(corners, FLOAT, "VEC3", ARRAY_BUFFER, minmax=True),
             "NORMAL": s.accessor([(0.0, 1.0, 0.0)] * 4, FLOAT, "VEC3", ARRAY_BUFFER)}
    for k in uv_sets:
        attrs["TEXCOORD_%d" % k] = s.accessor(uvs, FLOAT, "VEC2", ARRAY_BUFFER)
    s.j["meshes"].append({"name": "Quad", "primitives": [{"attributes": attrs, "mode": mode, "material": 0}]})
    return s


def png(width, height, rgb=(200, 200, 200), idat=None):
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    raw = b"".join(b"\0" + bytes(rgb) * width for _ in range(height)) if idat is None else None
    data = idat if idat is not None else zlib.compress(raw, 9)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", data) + chunk(b"IEND", b""))


def with_normal_map(s, index=0, tangents=None, tangent_type="VEC4"):
    """normalTexture (a flat 1x1 PNG read through TEXCOORD_1); with `tangents`, a TANGENT attribute of
    those rows (FLOAT, `tangent_type`)."""
    s.j["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png(1, 1, (128, 128, 255))).decode()}]
    s.j["textures"] = [{"source": 0}]
    s.j["materials"][0]["normalTexture"] = {"index": index, "texCoord": 1}
    if tangents is not None:
        s.j["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = s.accessor(tangents, FLOAT, tangent_type, ARRAY_BUFFER)
    return s


def with_texture(s, image):
    s.j["images"] = [image]
    s.j["textures"] = [{"source": 0}]
    s.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0, "texCoord": 1}
    return s


def glb(json_bytes, bin_bytes, version=2, magic=b"glTF"):
    j = pad4(json_bytes, b" ")
    out = struct.pack("<I4s", len(j), b"JSON") + j
    if bin_bytes is not None:
        b = pad4(bin_bytes)
        out += struct.pack("<I4s", len(b), b"BIN\0") + b
    return magic + struct.pack("<II", version, 12 + len(out)) + out


def glb_scene(s):
    s.finish_buffer(uri=None)
    return s


# ----------------------------------------------------------------------------- cases
CASES = []  # (filename, bytes, extra_files{name: bytes}, args, exit, substring, warning, comment)


def case(name, data, exit, sub, args="-", warn="-", extra=None, note=""):
    CASES.append((name, data, extra or {}, args, exit, sub, warn, note))


def gltf_case(name, s, exit, sub, uri="data", **kw):
    s.finish_buffer(uri) if not s.j["buffers"] else None
    case(name, s.gltf(), exit, sub, **kw)


def mutate(fn, **cube_kw):
    s = cube(**cube_kw)
    s.finish_buffer()
    fn(s.j)
    return s


def set_bin_floats(s, acc_index, vertex, values):
    """Overwrite floats of one element of an accessor in s.bin (before finish_buffer)."""
    acc = s.j["accessors"][acc_index]
    bv = s.j["bufferViews"][acc["bufferView"]]
    n = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[acc["type"]]
    off = bv["byteOffset"] + acc.get("byteOffset", 0) + vertex * 4 * n
    s.bin = s.bin[:off] + struct.pack("<" + "f" * len(values), *values) + s.bin[off + 4 * len(values):]


def build():
    # --- valid baselines (exit 0) ------------------------------------------------------
    gltf_case("valid_cube.gltf", cube(), 0, "-", note="baseline: the scene every hostile file derives from")
    s = cube(); s.finish_buffer("valid_cube_external.bin")
    case("valid_cube_external.gltf", s.gltf(), 0, "-", extra={"valid_cube_external.bin": s.bin},
         note="baseline with an external .bin")
    s = glb_scene(cube())
    case("valid_cube.glb", glb(s.gltf(), s.bin), 0, "-", note="baseline as GLB")
    gltf_case("valid_uv0_only.gltf", cube(uv_sets=(0,)), 0, "-", args="--uv 0",
              note="only TEXCOORD_0, selected with --uv 0")
    gltf_case("valid_no_normals.gltf", cube(normals=False), 0, "-",
              note="NORMAL is optional: flat normals are computed")
    gltf_case("valid_uint_indices.gltf", cube(idx_type=UINT), 0, "-", note="32-bit indices")
    gltf_case("valid_ubyte_indices.gltf", cube(idx_type=UBYTE), 0, "-", note="8-bit indices")
    gltf_case("valid_unindexed.gltf", cube(idx=False, pos=[cube_geometry()[0][i] for i in cube_geometry()[3]],
              nrm=[cube_geometry()[1][i] for i in cube_geometry()[3]],
              uv=[cube_geometry()[2][i] for i in cube_geometry()[3]]), 0, "-", note="no indices")
    gltf_case("valid_texcoord1_normalized_u16.gltf", cube(uv_ctype=USHORT), 0, "-",
              note="TEXCOORD_1 as normalized unsigned short is valid glTF 2.0")
    gltf_case("valid_texture.gltf", with_texture(cube(), {
        "uri": "data:image/png;base64," + base64.b64encode(png(4, 4)).decode()}), 0, "-",
        note="base colour texture read through TEXCOORD_1")
    gltf_case("valid_normal_map.gltf", with_normal_map(cube()), 0, "-",
              note="normalTexture without TANGENT: tangents generated from TEXCOORD_1")
    gltf_case("valid_normal_map_tangents.gltf", with_normal_map(cube(), tangents=[(1.0, 0.0, 0.0, 1.0)] * 24), 0, "-",
              note="normalTexture with a TANGENT attribute")

    s = cube()
    p0 = cube_geometry()[0][0]
    s.j["accessors"][A_POS]["sparse"] = {
        "count": 1,
        "indices": {"bufferView": s.view(struct.pack("<H", 0) + b"\0\0"), "componentType": USHORT},
        "values": {"bufferView": s.view(struct.pack("<3f", *p0))}}
    gltf_case("valid_sparse_position.gltf", s, 0, "-", note="sparse accessor (legal) on POSITION")
    gltf_case("valid_triangle_strip.gltf", quad(5), 0, "-", note="mode 5 converted to triangles")
    gltf_case("valid_triangle_fan.gltf", quad(6), 0, "-", note="mode 6 converted to triangles")

    # --- repairable (exit 0 + warning) --------------------------------------------------
    g = cube_geometry()
    gltf_case("repair_degenerate_repeated_index.gltf", cube(idx=g[3] + [0, 0, 1]), 0, "-", warn="*",
              note="one triangle (0,0,1) among 12 good ones: dropped with a warning")
    pos = g[0] + [(2.0, 0.0, 0.0), (3.0, 0.0, 0.0), (4.0, 0.0, 0.0)]
    gltf_case("repair_degenerate_collinear.gltf", cube(
        pos=pos, nrm=g[1] + [(0.0, 1.0, 0.0)] * 3, uv=g[2] + [(0.01, 0.99), (0.02, 0.99), (0.03, 0.99)],
        idx=g[3] + [24, 25, 26]), 0, "-", warn="*", note="zero-area triangle of 3 collinear points")
    nrm = list(g[1]); nrm[0] = nrm[5] = (0.0, 0.0, 0.0)
    gltf_case("repair_zero_normals.gltf", cube(nrm=nrm), 0, "-", warn="*", note="zero-length normals")
    nrm = list(g[1]); nrm[0] = (math.nan, math.nan, math.nan)
    gltf_case("repair_nan_normal.gltf", cube(nrm=nrm), 0, "-", warn="*", note="NaN normal recomputed")
    gltf_case("repair_unnormalized_normals.gltf", cube(nrm=[(3 * a, 3 * b, 3 * c) for a, b, c in g[1]]),
              0, "-", warn="*", note="normals of length 3 renormalized")
    s = cube()
    s.j["meshes"][0]["primitives"].append({"attributes": {"POSITION": A_POS}, "mode": 1})
    gltf_case("repair_lines_beside_triangles.gltf", s, 0, "-", warn="*",
              note="a LINES primitive next to triangles is skipped with a warning")

    # --- document level -----------------------------------------------------------------
    case("empty_file.gltf", b"", 2, "*", note="0 bytes")
    case("not_json.gltf", b"this is not JSON {\n", 2, "*")
    case("json_array.gltf", b"[{\"asset\":{\"version\":\"2.0\"}}]", 2, "*", note="top level is an array")
    case("json_truncated.gltf", cube().gltf()[:150], 2, "*", note="JSON cut mid-document")
    case("binary_garbage.gltf", bytes((i * 37 + 11) % 256 for i in range(512)), 2, "*")
    s = cube(); s.finish_buffer()
    extras_depth = 8000
    doc = s.gltf().decode()
    doc = doc[:-1] + ',"extras":' + "[" * extras_depth + "]" * extras_depth + "}"
    case("deep_json_nesting.gltf", doc.encode(), "0|2", "*",
         note="valid JSON nested 8000 deep in extras: bake it or refuse it, never overflow the stack")
    gltf_case("asset_version_1.gltf", mutate(lambda j: j["asset"].update(version="1.0")), 2, "asset",
              note="glTF 1.0 is not supported")
    gltf_case("asset_version_3.gltf", mutate(lambda j: j["asset"].update(version="3.0")), 2, "asset")
    gltf_case("asset_missing.gltf", mutate(lambda j: j.pop("asset")), 2, "asset")
    gltf_case("asset_minversion_2_1.gltf", mutate(lambda j: j["asset"].update(version="2.1", minVersion="2.1")),
              2, "asset", note="minVersion 2.1 requires a loader newer than 2.0")
    gltf_case("extension_required_unknown.gltf",
              mutate(lambda j: j.update(extensionsUsed=["EXT_exitance_unknown"],
                                        extensionsRequired=["EXT_exitance_unknown"])),
              2, "EXT_exitance_unknown")

    # --- buffers ------------------------------------------------------------------------
    s = cube(); s.finish_buffer("missing_external_bin.bin")
    case("missing_external_bin.gltf", s.gltf(), 2, "buffer 0", note=".bin file does not exist")
    s = cube(); s.finish_buffer("buffer_bytelength_gt_file.bin")
    s.j["buffers"][0]["byteLength"] = 4096
    case("buffer_bytelength_gt_file.gltf", s.gltf(), 2, "buffer 0",
         extra={"buffer_bytelength_gt_file.bin": s.bin}, note="byteLength 4096, the file holds 1032 bytes")
    gltf_case("buffer_bad_base64.gltf", mutate(lambda j: j["buffers"][0].update(
        uri="data:application/octet-stream;base64,@@@not*base64!!!")), 2, "buffer 0")
    gltf_case("buffer_datauri_short.gltf", mutate(lambda j: j["buffers"][0].update(
        uri="data:application/octet-stream;base64," + base64.b64encode(b"\0" * 64).decode())), 2, "buffer 0",
        note="data URI decodes to 64 bytes, byteLength says 1032")
    gltf_case("buffer_uri_directory.gltf", mutate(lambda j: j["buffers"][0].update(uri=".")), 2, "buffer 0",
              note="uri names a directory")
    gltf_case("buffer_uri_dev_zero.gltf", mutate(lambda j: j["buffers"][0].update(uri="/dev/zero")), 2,
              "buffer 0|no triangle", note="endless device file: refuse it, or read byteLength zeros "
              "(then every triangle is degenerate); never hang")
    gltf_case("buffer_uri_http.gltf", mutate(lambda j: j["buffers"][0].update(uri="http://127.0.0.1:9/x.bin")),
              2, "buffer 0", note="remote URI: a baker must not fetch it")
    gltf_case("buffer_missing_uri.gltf", mutate(lambda j: j["buffers"][0].pop("uri")), 2, "buffer 0",
              note="a .gltf buffer without uri has no data (only a GLB's first buffer may)")

    # --- bufferViews --------------------------------------------------------------------
    def view_past_buffer(j):
        bv = j["bufferViews"][3]
        bv["byteLength"] = j["buffers"][0]["byteLength"] - bv["byteOffset"] + 8
    gltf_case("bufferview_past_buffer.gltf", mutate(view_past_buffer),
              2, "bufferView 3", note="the index view ends 8 bytes after the buffer")
    gltf_case("bufferview_offset_huge.gltf", mutate(lambda j: j["bufferViews"][1].update(
        byteOffset=18446744073709551600)), 2, "bufferView 1", note="byteOffset near 2^64: must not wrap")
    gltf_case("bufferview_buffer_oob.gltf", mutate(lambda j: j["bufferViews"][0].update(buffer=3)), 2,
              "bufferView 0")
    gltf_case("bytestride_negative.gltf", mutate(lambda j: j["bufferViews"][0].update(byteStride=-12)), 2,
              "bufferView 0")
    gltf_case("bytestride_huge.gltf", mutate(lambda j: j["bufferViews"][0].update(byteStride=2147483648)), 2,
              "bufferView 0|accessor 0")
    gltf_case("bytestride_too_small.gltf", mutate(lambda j: j["bufferViews"][0].update(byteStride=4)), 2,
              "bufferView 0|accessor 0", note="stride 4 < VEC3 float element size 12")

    # --- accessors ----------------------------------------------------------------------
    gltf_case("accessor_past_bufferview.gltf", mutate(lambda j: j["accessors"][A_POS].update(byteOffset=12)),
              2, "accessor 0", note="12 + 12*23 + 12 = 300 > 288")
    gltf_case("accessor_count_past_bufferview.gltf", mutate(lambda j: j["accessors"][A_NRM].update(count=25)),
              2, "accessor 1", note="25 normals in a 288-byte view")

    def strided(j):
        j["bufferViews"][0]["byteStride"] = 16
    gltf_case("accessor_stride_past_bufferview.gltf", mutate(strided), 2, "accessor 0|bufferView 0",
              note="stride 16: 16*23 + 12 = 380 > 288")

    def past_buffer(j):  # the view fits its buffer only when byteLength is believed
        j["bufferViews"][3]["byteLength"] = 72
        j["accessors"][A_IDX]["count"] = 40
    gltf_case("accessor_indices_past_bufferview.gltf", mutate(past_buffer), 2, "accessor 3",
              note="40 indices in a 72-byte view (past the end of the buffer too)")
    s = cube()  # the same TEXCOORD_1 floats, stored 2 bytes into a view of their own
    s.j["accessors"][A_UV1].update(bufferView=s.view(b"\0\0" + pack("ff", cube_geometry()[2]), ARRAY_BUFFER),
                                   byteOffset=2)
    gltf_case("accessor_misaligned.gltf", s, 2, "accessor 2", note="float accessor at byteOffset 2")
    gltf_case("accessor_count_2pow31.gltf", mutate(lambda j: j["accessors"][A_POS].update(count=2147483648)),
              2, "accessor 0", note="giant declared count must not be allocated or overflow")
    gltf_case("accessor_count_2pow32_minus_1.gltf",
              mutate(lambda j: j["accessors"][A_IDX].update(count=4294967295)), 2, "accessor 3")
    gltf_case("accessor_count_zero.gltf", mutate(lambda j: j["accessors"][A_NRM].update(count=0)), 2,
              "accessor 1|mesh 0 primitive 0", note="count must be >= 1")
    gltf_case("accessor_count_negative.gltf", mutate(lambda j: j["accessors"][A_POS].update(count=-1)), 2,
              "accessor 0")
    gltf_case("accessor_count_string.gltf", mutate(lambda j: j["accessors"][A_POS].update(count="24")), 2,
              "accessor 0", note="schema: count is an integer")
    gltf_case("accessor_count_fractional.gltf", mutate(lambda j: j["accessors"][A_NRM].update(count=23.5)), 2,
              "accessor 1")
    gltf_case("accessor_bufferview_oob.gltf", mutate(lambda j: j["accessors"][A_NRM].update(bufferView=42)), 2,
              "accessor 1")
    gltf_case("componenttype_invalid.gltf", mutate(lambda j: j["accessors"][A_POS].update(componentType=5130)),
              2, "accessor 0", note="5130 (GL_DOUBLE) is not a glTF componentType")
    gltf_case("componenttype_zero.gltf", mutate(lambda j: j["accessors"][A_UV1].update(componentType=0)), 2,
              "accessor 2")
    gltf_case("accessor_type_invalid.gltf", mutate(lambda j: j["accessors"][A_POS].update(type="VEC7")), 2,
              "accessor 0")
    gltf_case("position_vec2.gltf", mutate(lambda j: j["accessors"][A_POS].update(type="VEC2")), 2,
              "accessor 0|mesh 0 primitive 0", note="POSITION must be VEC3 float")
    gltf_case("position_ushort.gltf", mutate(lambda j: j["accessors"][A_POS].update(componentType=USHORT)), 2,
              "accessor 0|mesh 0 primitive 0", note="POSITION as unsigned short needs KHR_mesh_quantization")
    gltf_case("normal_vec4.gltf", mutate(lambda j: j["accessors"][A_NRM].update(type="VEC4", count=18)), 2,
              "accessor 1|mesh 0 primitive 0")
    gltf_case("texcoord1_vec3.gltf", mutate(lambda j: j["accessors"][A_UV1].update(type="VEC3", count=16)), 2,
              "accessor 2|mesh 0 primitive 0")
    gltf_case("texcoord1_ushort_not_normalized.gltf",
              mutate(lambda j: j["accessors"][A_UV1].pop("normalized"), uv_ctype=USHORT), 2,
              "accessor 2|mesh 0 primitive 0", note="integer TEXCOORD must be normalized")
    gltf_case("indices_float.gltf", mutate(lambda j: j["accessors"][A_IDX].update(componentType=FLOAT, count=18)),
              2, "accessor 3|mesh 0 primitive 0", note="indices must be unsigned integers")
    gltf_case("indices_vec3.gltf", mutate(lambda j: j["accessors"][A_IDX].update(type="VEC3", count=12)), 2,
              "accessor 3|mesh 0 primitive 0", note="indices must be SCALAR")

    # --- attribute values -----------------------------------------------------------------
    s = cube(); set_bin_floats(s, A_POS, 5, [math.nan])
    gltf_case("position_nan.gltf", s, 2, "accessor 0|mesh 0 primitive 0", note="NaN in POSITION")
    s = cube(); set_bin_floats(s, A_POS, 7, [0.5, math.inf, 0.5])
    gltf_case("position_inf.gltf", s, 2, "accessor 0|mesh 0 primitive 0", note="+Inf in POSITION")
    s = cube(); set_bin_floats(s, A_POS, 0, [-math.inf])
    gltf_case("position_neg_inf.gltf", s, 2, "accessor 0|mesh 0 primitive 0")
    s = cube(); set_bin_floats(s, A_UV1, 3, [math.nan, 0.5])
    gltf_case("texcoord1_nan.gltf", s, 2, "accessor 2|mesh 0 primitive 0", note="NaN in TEXCOORD_1")
    s = cube()
    s.j["accessors"][A_POS]["sparse"] = {
        "count": 1,
        "indices": {"bufferView": s.view(struct.pack("<H", 2) + b"\0\0"), "componentType": USHORT},
        "values": {"bufferView": s.view(struct.pack("<3f", math.nan, 0.0, 0.0))}}
    gltf_case("position_nan_via_sparse.gltf", s, 2, "accessor 0|mesh 0 primitive 0",
              note="NaN only appears after applying a sparse substitution")

    # --- sparse -----------------------------------------------------------------------------
    def sparse_case(name, indices, note):
        s = cube()
        vals = [cube_geometry()[0][0]] * len(indices)
        s.j["accessors"][A_POS]["sparse"] = {
            "count": len(indices),
            "indices": {"bufferView": s.view(pad4(struct.pack("<%dH" % len(indices), *indices))),
                        "componentType": USHORT},
            "values": {"bufferView": s.view(b"".join(struct.pack("<3f", *v) for v in vals))}}
        gltf_case(name, s, 2, "accessor 0", note=note)
    sparse_case("sparse_indices_oob.gltf", [3, 30], "sparse index 30 >= count 24")
    sparse_case("sparse_indices_not_increasing.gltf", [5, 3], "sparse indices 5, 3")
    sparse_case("sparse_indices_duplicate.gltf", [4, 4], "sparse indices 4, 4 (must be strictly increasing)")
    s = cube()
    s.j["accessors"][A_POS]["sparse"] = {
        "count": 1000000,
        "indices": {"bufferView": s.view(b"\0\0\0\0"), "componentType": USHORT},
        "values": {"bufferView": s.view(b"\0" * 12)}}
    gltf_case("sparse_count_huge.gltf", s, 2, "accessor 0", note="sparse.count 1e6 > accessor count and > views")

    # --- meshes and primitives ----------------------------------------------------------
    idx = list(g[3]); idx[7] = 24
    gltf_case("index_out_of_range.gltf", cube(idx=idx), 2, "accessor 3|mesh 0 primitive 0",
              note="index 24 with 24 vertices")
    idx = list(g[3]); idx[0] = 65535
    gltf_case("index_max_ushort.gltf", cube(idx=idx), 2, "accessor 3|mesh 0 primitive 0",
              note="index 65535 (primitive restart value is not allowed in glTF)")
    gltf_case("index_count_not_multiple_of_3.gltf", mutate(lambda j: j["accessors"][A_IDX].update(count=35)),
              2, "accessor 3|mesh 0 primitive 0", note="35 indices in TRIANGLES mode")
    gltf_case("attribute_counts_differ.gltf", mutate(lambda j: j["accessors"][A_UV1].update(count=20)), 2,
              "mesh 0 primitive 0|accessor 2", note="TEXCOORD_1 has 20 elements, POSITION 24")
    gltf_case("attribute_accessor_oob.gltf", mutate(lambda j: j["meshes"][0]["primitives"][0]["attributes"]
                                                     .update(TEXCOORD_1=17)), 2, "mesh 0 primitive 0|accessor 17")
    gltf_case("indices_accessor_oob.gltf", mutate(lambda j: j["meshes"][0]["primitives"][0].update(indices=-1)),
              2, "mesh 0 primitive 0")
    gltf_case("primitive_without_position.gltf", mutate(lambda j: j["meshes"][0]["primitives"][0]["attributes"]
                                                         .pop("POSITION")), 2, "mesh 0 primitive 0|no triangle",
              note="glTF says skip a primitive without POSITION; then nothing is left")
    gltf_case("primitive_mode_invalid.gltf", mutate(lambda j: j["meshes"][0]["primitives"][0].update(mode=9)), 2,
              "mesh 0 primitive 0")
    gltf_case("mesh_no_primitives.gltf", mutate(lambda j: j["meshes"][0].update(primitives=[])), 2, "mesh 0",
              note="primitives must have at least one item")
    # Baked without probes and SVO: those stages are not what these rows test (CI time).
    gltf_case("mesh_without_texcoord1.gltf", cube(uv_sets=()), 0, "-", args="--probes none --voxel-resolution none",
              warn="*", note="no lightmap UVs at all: generated, with a warning naming the mesh")
    gltf_case("mesh_only_texcoord0.gltf", cube(uv_sets=(0,)), 0, "-", args="--probes none --voxel-resolution none",
              warn="*", note="TEXCOORD_0 present but --uv 0 not given: TEXCOORD_1 generated, with a warning")
    gltf_case("mesh_only_texcoord1_with_uv0.gltf", cube(uv_sets=(1,)), 0, "-",
              args="--uv 0 --probes none --voxel-resolution none", warn="*",
              note="--uv 0 asked for TEXCOORD_0, which is absent: generated, with a warning")
    gltf_case("points_only.gltf", quad(0), 2, "no triangle", warn="*",
              note="POINTS are skipped (warning), nothing left to bake")
    gltf_case("lines_only.gltf", quad(1), 2, "no triangle", warn="*")
    gltf_case("line_strip_only.gltf", quad(3), 2, "no triangle", warn="*")
    gltf_case("all_triangles_degenerate.gltf", cube(pos=[(0.0, 0.0, 0.0)] * 24), 2, "no triangle", warn="*",
              note="every triangle has zero area")
    gltf_case("material_index_oob.gltf", mutate(lambda j: j["meshes"][0]["primitives"][0].update(material=7)), 2,
              "mesh 0 primitive 0|material 7")

    # --- materials, textures, images ----------------------------------------------------
    gltf_case("texture_index_oob.gltf", mutate(lambda j: j["materials"][0]["pbrMetallicRoughness"].update(
        baseColorTexture={"index": 9, "texCoord": 1})), 2, "material 0|texture 9")
    gltf_case("normal_texture_index_oob.gltf", with_normal_map(cube(), index=3), 2, "material 0",
              note="normalTexture points at a texture that does not exist")
    gltf_case("tangent_vec3.gltf", with_normal_map(cube(), tangents=[(1.0, 0.0, 0.0)] * 24, tangent_type="VEC3"), 2,
              "mesh 0 primitive 0|accessor 5", note="TANGENT must be VEC4 FLOAT")
    gltf_case("tangent_short_count.gltf", with_normal_map(cube(), tangents=[(1.0, 0.0, 0.0, 1.0)] * 23), 2,
              "mesh 0 primitive 0|accessor 5", note="23 tangents for 24 vertices")
    gltf_case("tangent_nan.gltf", with_normal_map(cube(), tangents=[(float("nan"), 0.0, 0.0, 1.0)] + [(1.0, 0.0, 0.0, 1.0)] * 23),
              2, "accessor 5", note="a NaN tangent")
    s = with_texture(cube(), {"uri": "data:image/png;base64," + base64.b64encode(png(4, 4)).decode()})
    s.j["textures"][0]["source"] = 4
    gltf_case("image_index_oob.gltf", s, 2, "texture 0|image 4")
    gltf_case("image_missing_file.gltf", with_texture(cube(), {"uri": "image_missing_file.png"}), 2, "image 0")
    gltf_case("image_uri_path_traversal.gltf", with_texture(cube(), {"uri": "../../../../../../../../etc/passwd"}),
              2, "image 0", note="escapes the scene folder; not an image either way")
    gltf_case("image_corrupt_datauri.gltf", with_texture(cube(), {
        "uri": "data:image/png;base64," + base64.b64encode(b"\x89PNG\r\n\x1a\n" + b"garbage" * 20).decode()}),
        2, "image 0", note="PNG signature followed by garbage")
    case("image_corrupt_file.gltf", (lambda s: (s.finish_buffer(), s.gltf())[1])(
        with_texture(cube(), {"uri": "image_corrupt_file.png"})), 2, "image 0",
        extra={"image_corrupt_file.png": png(64, 64)[:60]}, note="PNG truncated after 60 bytes")
    gltf_case("image_not_an_image.gltf", with_texture(cube(), {
        "uri": "data:image/png;base64," + base64.b64encode(b"hello, this is text\n" * 4).decode()}), 2, "image 0")
    gltf_case("image_huge_dimensions.gltf", with_texture(cube(), {
        "uri": "data:image/png;base64," + base64.b64encode(
            png(1000000, 1000000, idat=zlib.compress(b"\0" * 64))).decode()}), 2, "image 0",
        note="IHDR claims 1e6 x 1e6 pixels (decompression bomb); must not allocate 3 TB")

    # --- nodes and scenes ---------------------------------------------------------------
    def cyclic(j):
        j["nodes"] = [{"children": [1]}, {"mesh": 0, "children": [0]}]
    gltf_case("cyclic_nodes.gltf", mutate(cyclic), 2, "node 0|node 1", note="node 0 -> 1 -> 0")
    gltf_case("self_parent_node.gltf", mutate(lambda j: j["nodes"][0].update(children=[0])), 2, "node 0")

    def two_parents(j):
        j["scenes"][0]["nodes"] = [0, 1]
        j["nodes"] = [{"children": [2]}, {"children": [2]}, {"mesh": 0}]
    gltf_case("node_two_parents.gltf", mutate(two_parents), 2, "node 2",
              note="node hierarchy must be disjoint trees")
    gltf_case("node_child_oob.gltf", mutate(lambda j: j["nodes"][0].update(children=[99])), 2, "node 0|node 99")
    gltf_case("scene_root_oob.gltf", mutate(lambda j: j["scenes"][0].update(nodes=[99])), 2, "scene 0|node 99")
    gltf_case("scene_index_oob.gltf", mutate(lambda j: j.update(scene=3)), 2, "scene 3|: scene")
    gltf_case("scene_no_nodes.gltf", mutate(lambda j: j["scenes"][0].pop("nodes")), 2, "no triangle",
              note="an empty scene: nothing to bake")
    gltf_case("mesh_index_oob.gltf", mutate(lambda j: j["nodes"][0].update(mesh=5)), 2, "node 0|mesh 5")
    gltf_case("matrix_and_trs.gltf", mutate(lambda j: j["nodes"][0].update(
        matrix=[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1], translation=[1, 0, 0])), 2, "node 0",
        note="matrix and TRS on one node")
    s = cube(); s.finish_buffer()
    s.j["nodes"][0]["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    doc = s.gltf().replace(b'"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]',
                           b'"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,1e999,0,0,1]')
    case("matrix_nonfinite.gltf", doc, 2, "node 0|1e999",
         note="1e999 overflows a double; naming the node or quoting the number both locate it")
    s = cube(); s.finish_buffer()
    doc = s.gltf().replace(b'"name":"Cube"}],"meshes"', b'"name":"Cube","translation":[0,-1e400,0]}],"meshes"')
    assert b"-1e400" in doc
    case("translation_nonfinite.gltf", doc, 2, "node 0|1e400")
    gltf_case("matrix_wrong_length.gltf", mutate(lambda j: j["nodes"][0].update(matrix=[1, 0, 0, 0, 1, 0, 0, 0, 1])),
              2, "node 0", note="9 numbers instead of 16")
    gltf_case("scale_zero.gltf", mutate(lambda j: j["nodes"][0].update(scale=[0, 0, 0])), 2, "no triangle",
              note="zero scale collapses every triangle")

    # 10 000-deep chain; the cube hangs from the deepest node.  Bigger than the 20 KB
    # guideline by necessity (about 17 bytes per node), hence written without spaces.
    depth = 10000
    s = cube(); s.finish_buffer()
    s.j["nodes"] = [{"children": [i + 1]} for i in range(depth - 1)] + [{"mesh": 0}]
    case("deep_nodes_10000.gltf", s.gltf(), "0|2", "node",
         note="valid glTF; bake it (iteratively) or refuse it naming a node; never overflow the stack")

    # --- GLB container ------------------------------------------------------------------
    s = glb_scene(cube()); good = glb(s.gltf(), s.bin)
    case("glb_wrong_magic.glb", b"glTf" + good[4:], 2, "glb header")
    case("glb_truncated_header.glb", good[:9], 2, "glb header")
    case("glb_version_1.glb", good[:4] + struct.pack("<I", 1) + good[8:], 2, "glb header")
    case("glb_length_beyond_file.glb", good[:8] + struct.pack("<I", len(good) + 1000) + good[12:], 2, "glb",
         note="header length says 1000 bytes more than the file")
    case("glb_truncated_chunk.glb", good[:len(good) - 200], 2, "glb|buffer 0",
         note="file cut inside the BIN chunk")
    case("glb_truncated_chunk_header.glb", good[:12 + 5], 2, "glb", note="file cut inside the JSON chunk header")
    jl = struct.unpack("<I", good[12:16])[0]
    case("glb_json_chunk_beyond_file.glb", good[:12] + struct.pack("<I", 0x7FFFFFF0) + good[16:], 2, "glb",
         note="JSON chunkLength 2^31-16")
    case("glb_json_chunk_wrong_type.glb", good[:16] + b"BIN\0" + good[20:], 2, "glb",
         note="first chunk is not JSON")
    s = glb_scene(cube())
    case("glb_bin_chunk_short.glb", glb(s.gltf(), s.bin[:400]), 2, "buffer 0|glb",
         note="BIN chunk 400 bytes, buffer byteLength 1032")
    s = glb_scene(cube())
    case("glb_no_bin_chunk.glb", glb(s.gltf(), None), 2, "buffer 0|glb", note="buffer 0 has no uri and no BIN chunk")
    case("glb_empty_json.glb", glb(b"", None), 2, "*", note="JSON chunk of 4 spaces")


# ----------------------------------------------------------------------------- output
HEADER = """\
# Bad-input expectations for bake (tests/badinput/run_bad_input.py).
# Columns (tab-separated):
#   corpus     hostile = tests/badinput/hostile/, assimp = --assimp-root (Debian assimp-testmodels glTF2/)
#   path       file relative to the corpus root
#   args       extra bake arguments ('-' for none); the runner always adds -o OUT --spp 1 --texel-density 4
#   exit       expected exit status; 'a|b' accepts either (only for resource limits: bake it or refuse it)
#   error      when the exit is 2: the error line must contain one of these '|'-separated substrings
#              (the element, e.g. 'accessor 3'); '*' = any element; '-' when a success is expected
#   warning    '*' = stderr must hold at least one 'bake: warning:' line; '-' = not required
#   note       free text
# Rows with corpus 'hostile' are rewritten by make_hostile_inputs.py; edit the others by hand.
"""


def main():
    build()
    if os.path.isdir(OUT):
        shutil.rmtree(OUT)
    os.makedirs(OUT)
    rows = []
    names = set()
    for name, data, extra, args, exit_, sub, warn, note in CASES:
        assert name not in names, name
        names.add(name)
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(data)
        for ename, edata in extra.items():
            with open(os.path.join(OUT, ename), "wb") as f:
                f.write(edata)
        big = len(data) > 20000 and not name.startswith("deep_nodes")
        assert not big, "%s is %d bytes" % (name, len(data))
        rows.append("\t".join(["hostile", name, args, str(exit_), sub, warn, note or "-"]))
    kept = []
    if os.path.exists(TSV):
        with open(TSV) as f:
            for line in f:
                line = line.rstrip("\n")
                if line.startswith("#") or not line.strip():
                    continue
                if line.split("\t")[0] != "hostile":
                    kept.append(line)
    with open(TSV, "w") as f:
        f.write(HEADER)
        f.write("\n".join(rows + kept) + "\n")
    print("wrote %d hostile cases to %s; kept %d other rows" % (len(rows), OUT, len(kept)))


if __name__ == "__main__":
    sys.exit(main())
