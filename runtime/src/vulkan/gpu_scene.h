// The scene on the device: a LightingScene's records as the kernels read them (gpu_layout.h), the
// BVH4 in the chosen node layout, and per leaf slot a copy of its triangle's vertices for traversal.
// Materials and punctual lights can be updated in place (runtime edits): only those records and
// what depends on them are uploaded again. Moved geometry (same triangles, BVH refit) replaces the
// triangle records, BVH nodes and leaf copies in their buffers, of the same sizes.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/runtime/core/lighting_scene.h"
#include "gpu_surfaces.h"
#include "vulkan_context.h"
#include "wavefront_kernels.h"

namespace exitance::vulkan {

// Throws std::invalid_argument for a scene without a BVH4. Textures, COLOR_0 and MASK/BLEND are
// evaluated per point (gpu_surfaces.h, shaders/include/scene_access.glsl), image skies through
// environment_map.h.
void check_supported_by_vulkan(const LightingScene& scene);

class GpuScene {
 public:
  // `quantized_nodes`: 64-byte nodes with 8-bit child bounds (bvh_quantization.h), else 112-byte float nodes.
  GpuScene(Context& context, const LightingScene& scene, bool quantized_nodes);

  // `edited`: the scene this one was uploaded from, after set_material (lighting_scene.h): uploads
  // the materials (their power per area), the emitter list and CDF, the triangle records of
  // emitters joining or leaving the list (their flag), and the per-material surface records
  // (textures, alphaMode); when the edit makes the scene textured, its textures and corners too. At
  // the start of the next submission (Context::write_ranges_at_next_submission). Throws
  // std::invalid_argument when the scene's shape differs.
  void update_materials(const LightingScene& edited);
  // After set_punctual_light or a sky edit: uploads the punctual lights and their CDF, takes the
  // constant sky, and uploads the image sky (texels and CDFs, growing their buffers when the new
  // image is larger) or switches it off when the edited sky is constant.
  void update_lights(const LightingScene& edited);
  // The runtime's change estimate (path.h punctual_change_rays): after `edited`'s punctual lights,
  // `pairs` of records (each edited light as edited, then as it was at the base), the buffer grown
  // to fit. The kernels read them only when GpuParams::changed_light_pairs says so.
  // The punctual records with `pairs` after them, and the punctual CDF, in one submission.
  void set_changed_light_pairs(const LightingScene& edited, const std::vector<GpuPunctualLight>& pairs);
  // The punctual records and CDF alone, in one submission (edits of punctual lights).
  void update_punctual_lights(const LightingScene& edited);

  // After set_geometry (lighting_scene.h): uploads the triangles, the BVH nodes (in this scene's
  // node layout) and per-slot vertex copies, then what update_materials and update_lights upload,
  // and takes the bounds and extent. Throws std::invalid_argument when the scene's shape (counts,
  // BVH nodes and leaf slots, traversal stack bound) differs.
  void update_geometry(const LightingScene& edited);
  // After refresh_moved_triangles_from_source (lighting_scene.h): only the moved triangles' records
  // and leaf-slot vertex copies, the changed BVH nodes, the punctual lights and CDF, and when an
  // emitter moved (`emitters_changed`) the emitter CDF and total power, or, when the emitter list
  // changed or `materials_changed` (material edits in the same call), what update_materials
  // uploads; takes the bounds and extent. The device scene then equals update_geometry's. Throws
  // std::invalid_argument for a shape, link or index that is not this scene's.
  void update_moved_geometry(const LightingScene& edited, const Bvh4Links& links, const std::vector<uint32_t>& moved_triangles,
                             const std::vector<uint32_t>& changed_nodes, bool emitters_changed, bool materials_changed = false);

  void bind(DescriptorWrites& writes) const;  // kBindingBvhNodes .. kBindingPunctualCdf, kBindingSurfaces, kBindingEnvironment

  // What the kernels' parameters (GpuParams) take from the scene, current after updates.
  Vec3 sky() const { return sky_; }
  float extent() const { return extent_; }
  Vec3 bounds_lo() const { return bounds_lo_; }
  Vec3 bounds_hi() const { return bounds_hi_; }
  uint32_t emitter_count() const { return uint32_t(emitters_.size()); }
  float emitter_inverse_power() const { return emitter_inverse_power_; }
  const std::vector<uint32_t>& emitter_triangles() const { return emitters_; }  // the emitter list, in CDF order
  uint32_t punctual_count() const { return punctual_count_; }
  // The scene's light layers as laid out when it was built (LightingScene; fixed through edits).
  uint32_t light_layer_count() const { return light_layer_count_; }
  uint32_t punctual_light_layers() const { return punctual_light_layers_; }
  uint32_t surface_flags() const { return surface_flags_; }  // kSurface* (gpu_layout.h)
  uint32_t environment_width() const { return environment_width_; }  // 0: constant sky
  uint32_t environment_height() const { return environment_height_; }

  uint32_t traversal_stack_bound() const { return stack_bound_; }
  // Steps of one ray's traversal in a valid BVH: each inner node and leaf at most once (bvh.glsl
  // counts a fault beyond it). Fixed per scene: edits refit, never rebuild, the node arrays.
  uint32_t traversal_step_bound() const { return node_count_ + leaf_slots_ + 1u; }
  bool quantized_nodes() const { return quantized_; }
  uint32_t bvh_node_count() const { return node_count_; }
  size_t bvh_bytes() const;

 private:
  void check_same_shape(const LightingScene& edited) const;
  // Uploads `bytes` of `data` into `buffer`, first growing it when they do not fit (a material edit
  // can add emitters); the integrator writes its descriptors again before each bake.
  void upload_growing(Buffer& buffer, const void* data, size_t bytes);
  void grow(Buffer& buffer, size_t bytes);  // a larger buffer when `bytes` exceed it (contents not kept)
  // update_materials' writes appended to `writes` (buffers grown first; `surfaces` and `emitters`
  // hold what they copy until written), and what this scene records once they are written.
  void add_material_writes(const LightingScene& edited, std::vector<Context::RangeWrite>& writes, std::vector<Vec4>& surfaces,
                           std::vector<uint32_t>& emitters);
  void materials_uploaded(const LightingScene& edited);
  std::vector<Context::RangeWrite> punctual_writes(const LightingScene& edited) const;
  void update_environment(const LightingScene& edited);

  Context& context_;
  Buffer nodes_, leaf_triangles_, triangles_, materials_, emitter_cdf_, emitter_triangles_, punctual_lights_, punctual_cdf_;
  Buffer surfaces_;  // gpu_surfaces.h
  SurfaceLayout surface_layout_;
  bool surfaces_textured_ = false;  // the buffer holds the textures and corners too
  uint32_t surface_flags_ = 0;
  Buffer environment_;  // gpu_layout.h kBindingEnvironment
  std::vector<uint32_t> emitters_;  // uploaded emitter triangles: their records change with the next edit
  size_t triangle_count_ = 0, material_count_ = 0;
  uint32_t punctual_count_ = 0;
  uint32_t light_layer_count_ = 1, punctual_light_layers_ = 0;
  Vec3 sky_{0, 0, 0}, bounds_lo_{0, 0, 0}, bounds_hi_{0, 0, 0};
  float extent_ = 1.0f;
  float emitter_inverse_power_ = 0.0f;  // as uploaded with the emitter CDF
  uint32_t environment_width_ = 0, environment_height_ = 0;  // 0: constant sky
  uint32_t stack_bound_ = 8, node_count_ = 0, leaf_slots_ = 0;
  bool quantized_ = false;
};

}  // namespace exitance::vulkan
