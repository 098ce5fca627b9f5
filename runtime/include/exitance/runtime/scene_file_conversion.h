// Scene (+ texel G-buffer, atlas layout, probe grid layout, BVH) <-> scene.bin records
// (formats/include/exitance/formats/scene_file.h, layout in formats/scene_format.md).
//
// make_scene_file and restore_scene are inverse: restore_scene(make_scene_file(...)) gives back
// the scene field for field (bit for bit), the atlas layout (except capped_instances, not
// stored), the probe positions and states, the BVH, and the texel G-buffer bit for bit
// (texel_gbuffer_codec.h). Materials without textures and a constant sky only, for now.
// The BVH is formats' own record type (the GPU's BVH4 node layout, leaf slots as scene triangle
// indices); the Vulkan backend rebuilds its per-slot vertex copies from the scene on load.
#pragma once
#include "exitance/formats/scene_file.h"
#include "exitance/runtime/core/bvh4.h"
#include "exitance/runtime/lightmap_atlas.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

struct PersistedScene {
  Scene scene;
  TexelGBuffer gbuffer;
  AtlasLayout atlas;
  formats::ProbeGrid probes = formats::SceneFile::no_probe_grid();  // positions and states; SH zero
  formats::SceneBvh bvh;
  bool has_probe_grid() const { return !probes.probes.empty(); }
};

// Textures, bindings, alpha modes, vertex colours and the environment-map sky are stored as the
// lighting stage evaluates them (format version 2), so a scene read back lights bit-identically.
// Throws formats::FormatError naming what scene.bin cannot hold (an atlas rectangle per instance
// missing, a page over 65535 texels, ...) and, through encode_scene's validation when writing,
// anything else invalid.
// `probes` may be null (no probe grid); its SH coefficients are not stored.
formats::SceneFile make_scene_file(const Scene& scene, const TexelGBuffer& gbuffer, const AtlasLayout& atlas,
                                   const formats::ProbeGrid* probes, const formats::SceneBvh& bvh);

// The BVH4 as scene.bin's records and back (the same 112-byte node layout, leaf slots as scene
// triangle indices): exact copies.
formats::SceneBvh to_scene_bvh(const Bvh4& bvh);
Bvh4 to_bvh4(const formats::SceneBvh& records);

// `file` as read_scene returns it (validated); throws formats::FormatError if it is not consistent.
PersistedScene restore_scene(const formats::SceneFile& file);

}  // namespace exitance
