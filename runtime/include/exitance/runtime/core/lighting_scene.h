// The scene as every lighting backend reads it, built once by the offline stage (or from scene.bin)
// and handed to the backends: triangles, materials and lights in the GPU layout
// (runtime/common/.../gpu_layout.h), the light-selection CDFs, the BVH, and the source Scene for
// names, instances and what only the CPU reference evaluates today (textures).
#pragma once
#include <memory>
#include <vector>

#include "exitance/common/gpu_layout.h"
#include "exitance/runtime/core/bvh4.h"
#include "exitance/runtime/core/bvh4_refit.h"
#include "exitance/runtime/environment_sampler.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/world_box.h"

namespace exitance {

struct LightingScene {
  std::shared_ptr<const Scene> source;
  std::vector<GpuTriangle> triangles;        // one per scene triangle
  std::vector<GpuMaterial> materials;        // constant factors (textures: source, CPU only)
  std::vector<GpuPunctualLight> punctual_lights;
  std::vector<uint32_t> emitter_triangles;   // emissive triangles NEE picks from, by power
  std::vector<double> emitter_cdf;           // emitter_triangles.size() + 1 entries (at least 2)
  std::vector<float> emitter_areas;          // per emitter_triangles: an edit recomputes the moved ones only
  // 1 / the emitters' total power (0: no emitter). An emitter's material record holds its power per
  // area (GpuMaterial::emitter_power.x; the triangle's record flags it, p1_emitter.w): their product
  // is the area density with which NEE picks a point on it, so a move that changes the total, or an
  // emission edit, rewrites this value, the CDF (and the edited material records), no triangle record.
  float emitter_inverse_power = 0.0f;
  std::vector<double> punctual_cdf;          // punctual_lights.size() + 1 entries (at least 2), by power
  double punctual_power = 0.0;               // the luminance power that CDF is of, summed over the lights
  Vec3 sky{0, 0, 0};                         // constant sky radiance (when there is no environment map)
  EnvironmentSampler environment;            // enabled when the sky is an image
  Vec3 bounds_lo{0, 0, 0}, bounds_hi{0, 0, 0};
  float extent = 1.0f;                       // largest side of the bounds: the scale of ray-offset floors
  bool textured = false;  // materials vary per point (textures, MASK/BLEND, COLOR_0): CPU reference only
  Bvh4 bvh;
  // Light layers (exitance/common/light_layers.h), laid out once when the scene is built and kept
  // through edits (a layer's sums stay its light's): the sky, punctual_light_layers for the punctual
  // lights, one per material emissive then (up to the limit), one for materials made emissive later.
  // Each material's layer is in its record's emission.w too.
  uint32_t punctual_light_layers = 0;
  uint32_t light_layer_count = 1;
  std::vector<uint32_t> material_light_layers;

  uint32_t emitter_count() const { return uint32_t(emitter_triangles.size()); }
  uint32_t punctual_count() const { return uint32_t(punctual_lights.size()); }
};

// Derives the GPU-layout records and light distributions from `scene` and takes the BVH built over
// it. Emitters are chosen by power (area x luminance of the mean emission, x2 when double sided),
// punctual lights by power (point 4 pi I, spot 2 pi (1 - cos_outer) I, directional pi r^2 E over the
// scene's bounding sphere). An empty BVH is allowed (the CPU reference traces with Embree's own);
// throws std::invalid_argument when the BVH references a triangle the scene does not have.
LightingScene build_lighting_scene(std::shared_ptr<const Scene> scene, Bvh4 bvh);

// The light layers of `scene`'s lights and emissive materials, at most `limit` per kind (beyond it
// the last layer of the kind is shared): sets punctual_light_layers, light_layer_count,
// material_light_layers and the records' emission.w. build_lighting_scene lays them out with the
// default limit (kDefaultLightLayerLimit).
void lay_out_light_layers(LightingScene& scene, uint32_t limit);

// The radius of the bounds' sphere (centred on the bounds' centre; 1 without triangles): the disc a
// directional light's power crosses, and where the sky's and the sun's light subpaths start.
float scene_radius(const LightingScene& scene);

// After geometry moved (an instance transform edit, refresh/scene_edits.h): `edited` is the source
// scene with the same triangles (count, order, materials, instances) at new positions, and
// possibly other edits. Everything is derived again as build_lighting_scene does (triangle
// records, bounds, extent, emitter areas and CDF, light records and CDF, sky), over the current
// BVH refit to the new positions (bvh4_refit.h: same topology, no rebuild). Throws
// std::invalid_argument when the triangle count differs; `scene` is unchanged when it throws.
void set_geometry(LightingScene& scene, std::shared_ptr<const Scene> edited);

// Runtime edits in place: the record, the source Scene (copied on write, as others may share it)
// and what depends on them are recomputed as build_lighting_scene would: a material's record, the
// `textured` flag, the emitter distribution and every triangle's area pdf; a light's record and the
// punctual CDF. Geometry, BVH and sizes stay (an instance transform needs a BVH refit:
// set_geometry). Throw std::out_of_range for an index the scene does not have.
void set_material(LightingScene& scene, uint32_t index, const Material& material);
void set_punctual_light(LightingScene& scene, uint32_t index, const PunctualLight& light);

// After the listed lights (and the sky, when `sky`) changed in `scene.source` itself: a Scene its
// owner edits in place (the runtime's session, whose lighting scene reads its own scene), with no
// copy on write. The records of those lights, the punctual CDF and the sky, as build_lighting_scene
// derives them. Throws std::invalid_argument when the source's light count differs (nothing changed),
// std::out_of_range for a light index beyond it.
void refresh_lights_from_source(LightingScene& scene, const std::vector<uint32_t>& lights, bool sky);

// The same for materials edited in the source itself: their records, `textured` and the emitter
// distribution, as build_lighting_scene derives them. Throws as refresh_lights_from_source does.
void refresh_materials_from_source(LightingScene& scene, const std::vector<uint32_t>& materials);

// After triangles moved in the source itself (apply_scene_edits_in_place): `moved` ascending, with
// their vertices before (`moved_before`, 3 each), `bounds` the box of every source position now
// (the caller keeps it per instance rather than passing over the scene). The BVH refit over them
// (refit_bvh4_moved with `links`), their records, the bounds and extent, the emitter distribution
// when an emitter moved, the punctual records and CDF (directional powers follow the bounds): what
// set_geometry derives, without a pass over every triangle. Returns the BVH nodes that changed
// (ascending) and whether the emitter distribution was derived again. Throws
// std::invalid_argument when the source's triangle count differs (nothing changed).
struct MovedTrianglesRefresh {
  std::vector<uint32_t> bvh_nodes;
  bool emitters_changed = false;
};
MovedTrianglesRefresh refresh_moved_triangles_from_source(LightingScene& scene, const Bvh4Links& links,
                                                         const std::vector<uint32_t>& moved,
                                                         const std::vector<Vec3>& moved_before, const WorldBox& bounds);

}  // namespace exitance
