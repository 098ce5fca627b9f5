#include "gpu_scene.h"

#include <algorithm>
#include <cstring>
#include <iterator>
#include <stdexcept>
#include <string>

#include "bvh_quantization.h"
#include "gpu_surfaces.h"
#include "exitance/common/environment_map.h"
#include "exitance/runtime/core/scene_access.h"

namespace exitance::vulkan {
namespace {

static_assert(sizeof(GpuTriangle) == 96 && sizeof(GpuMaterial) == 48 && sizeof(GpuPunctualLight) == 48);

// Vulkan buffers cannot be empty.
template <typename T>
std::vector<T> at_least_one(const std::vector<T>& v) {
  return v.empty() ? std::vector<T>(1) : v;
}

template <typename T>
Buffer upload_new(Context& context, const std::vector<T>& data) {
  Buffer b = context.create_storage_buffer(data.size() * sizeof(T));
  context.upload(b, data.data(), data.size() * sizeof(T));
  return b;
}

// The same, with room for `extra` more records (a change estimate's light pairs, set later).
template <typename T>
Buffer upload_with_room(Context& context, const std::vector<T>& data, size_t extra) {
  Buffer b = context.create_storage_buffer((data.size() + extra) * sizeof(T));
  context.upload(b, data.data(), data.size() * sizeof(T));
  return b;
}

std::vector<uint32_t> node_words(const Bvh4& bvh, bool quantized) {
  if (quantized) return quantize_bvh4_nodes(bvh.nodes);
  std::vector<uint32_t> words(bvh.nodes.size() * sizeof(Bvh4Node) / 4);
  std::memcpy(words.data(), bvh.nodes.data(), words.size() * 4);
  return words;
}

// A leaf slot's triangle's vertices (and index, in the first w) where traversal reads them together.
void leaf_triangle_copy(const LightingScene& scene, size_t slot, Vec4 out[3]) {
  const uint32_t t = scene.bvh.leaf_triangles[slot];
  out[0] = Vec4(scene_triangle_vertex(scene, t, 0), uintBitsToFloat(t));
  out[1] = Vec4(scene_triangle_vertex(scene, t, 1), 0.0f);
  out[2] = Vec4(scene_triangle_vertex(scene, t, 2), 0.0f);
}

std::vector<Vec4> leaf_triangle_copies(const LightingScene& scene) {
  std::vector<Vec4> leaf(std::max<size_t>(scene.bvh.leaf_triangles.size(), 1) * 3);
  for (size_t slot = 0; slot < scene.bvh.leaf_triangles.size(); ++slot) leaf_triangle_copy(scene, slot, &leaf[slot * 3]);
  return leaf;
}

// The records of `triangles` (sorted, unique) as byte ranges, near ones joined.
std::vector<ByteRange> triangle_ranges(const std::vector<uint32_t>& triangles) {
  return byte_ranges(record_runs(triangles, sizeof(GpuTriangle)), sizeof(GpuTriangle));
}

// The image sky as the kernels read it (gpu_layout.h kBindingEnvironment): marginal CDF, row CDFs,
// then the rgb texels bit-copied two floats to a double; a placeholder when the sky is constant.
std::vector<double> environment_words(const LightingScene& scene) {
  if (!scene.environment.enabled()) return std::vector<double>(1);
  const uint32_t width = scene.environment.width(), height = scene.environment.height();
  const std::vector<double>& marginal = scene.environment.marginal_cdf();
  const std::vector<double>& rows = scene.environment.row_cdfs();
  const std::vector<float>& texels = scene.environment.texels();
  const size_t texels_offset = size_t(height) + 1 + size_t(height) * (size_t(width) + 1);
  const size_t words = texels_offset + (texels.size() + 1) / 2;
  if (marginal.size() != environment_rows_offset(height) || marginal.size() + rows.size() != texels_offset)
    throw std::logic_error("Vulkan backend: the environment CDFs do not have the layout the kernels read");
  if (words > size_t(UINT32_MAX))
    throw std::runtime_error("Vulkan backend: the environment map is too large (" + std::to_string(width) + " x " +
                             std::to_string(height) + " texels)");
  std::vector<double> packed(words, 0.0);
  std::copy(marginal.begin(), marginal.end(), packed.begin());
  std::copy(rows.begin(), rows.end(), packed.begin() + marginal.size());
  std::memcpy(packed.data() + texels_offset, texels.data(), texels.size() * sizeof(float));
  return packed;
}

}  // namespace

void check_supported_by_vulkan(const LightingScene& scene) {
  if (scene.bvh.nodes.empty()) throw std::invalid_argument("Vulkan backend: the scene has no BVH4 (build_bvh4 or scene.bin)");
}

GpuScene::GpuScene(Context& context, const LightingScene& scene, bool quantized_nodes)
    : context_(context),
      nodes_(upload_new(context, node_words(scene.bvh, quantized_nodes))),
      leaf_triangles_(upload_new(context, leaf_triangle_copies(scene))),
      triangles_(upload_new(context, at_least_one(scene.triangles))),
      materials_(upload_new(context, at_least_one(scene.materials))),
      emitter_cdf_(upload_new(context, scene.emitter_cdf)),
      emitter_triangles_(upload_new(context, at_least_one(scene.emitter_triangles))),
      punctual_lights_(upload_with_room(context, at_least_one(scene.punctual_lights), 2 * kMaxChangedLightPairs)),
      punctual_cdf_(upload_new(context, scene.punctual_cdf)),
      environment_(upload_new(context, environment_words(scene))),
      emitters_(scene.emitter_triangles),
      triangle_count_(scene.triangles.size()),
      material_count_(scene.materials.size()),
      punctual_count_(scene.punctual_count()),
      light_layer_count_(scene.light_layer_count),
      punctual_light_layers_(scene.punctual_light_layers),
      sky_(scene.sky),
      bounds_lo_(scene.bounds_lo),
      bounds_hi_(scene.bounds_hi),
      extent_(scene.extent),
      emitter_inverse_power_(scene.emitter_inverse_power),
      environment_width_(scene.environment.enabled() ? scene.environment.width() : 0),
      environment_height_(scene.environment.enabled() ? scene.environment.height() : 0),
      stack_bound_(std::max<uint32_t>(scene.bvh.stack_entries + 1, 8)),
      node_count_(uint32_t(scene.bvh.nodes.size())),
      leaf_slots_(uint32_t(scene.bvh.leaf_triangles.size())),
      quantized_(quantized_nodes) {
  surface_flags_ = vulkan::surface_flags(scene);
  const std::vector<Vec4> words = surface_words(scene, surface_layout_);
  upload_growing(surfaces_, words.data(), words.size() * sizeof(Vec4));
  surfaces_textured_ = scene.textured;
}

size_t GpuScene::bvh_bytes() const {
  return size_t(node_count_) * (quantized_ ? kQuantizedNodeWords * 4 : sizeof(Bvh4Node)) + size_t(leaf_slots_) * 48;
}

void GpuScene::bind(DescriptorWrites& writes) const {
  writes.set(kBindingBvhNodes, nodes_);
  writes.set(kBindingBvhTriangles, leaf_triangles_);
  writes.set(kBindingTriangles, triangles_);
  writes.set(kBindingMaterials, materials_);
  writes.set(kBindingEmitterCdf, emitter_cdf_);
  writes.set(kBindingEmitterTriangles, emitter_triangles_);
  writes.set(kBindingPunctualLights, punctual_lights_);
  writes.set(kBindingPunctualCdf, punctual_cdf_);
  writes.set(kBindingSurfaces, surfaces_);
  writes.set(kBindingEnvironment, environment_);
}

void GpuScene::check_same_shape(const LightingScene& edited) const {
  if (edited.triangles.size() != triangle_count_ || edited.materials.size() != material_count_ ||
      edited.punctual_count() != punctual_count_ || edited.bvh.nodes.size() != node_count_)
    throw std::invalid_argument("Vulkan backend: an update must keep the scene's triangles, materials, lights and BVH "
                                "(other edits need a new integrator)");
}

void GpuScene::upload_growing(Buffer& buffer, const void* data, size_t bytes) {
  grow(buffer, bytes);
  context_.upload(buffer, data, bytes);
}

void GpuScene::grow(Buffer& buffer, size_t bytes) {
  if (bytes > buffer.size()) buffer = context_.create_storage_buffer(bytes);
}

void GpuScene::update_materials(const LightingScene& edited) {
  check_same_shape(edited);
  check_supported_by_vulkan(edited);
  std::vector<Context::RangeWrite> writes;
  std::vector<Vec4> surfaces;
  std::vector<uint32_t> emitters;
  add_material_writes(edited, writes, surfaces, emitters);
  // Copied at the start of the next submission (before any kernel reads them): a material edit
  // waits for no upload of its own.
  context_.write_ranges_at_next_submission(writes);
  materials_uploaded(edited);
}

void GpuScene::add_material_writes(const LightingScene& edited, std::vector<Context::RangeWrite>& writes, std::vector<Vec4>& surfaces,
                                   std::vector<uint32_t>& emitters) {
  // The material records, the triangle records of old and new emitters (their power per area), the
  // emitter CDF and list (their buffers grown first when larger) and the surface records, in one
  // submission. A material edit cannot change textures or corners, so the surfaces are the header
  // and material records alone, unless the edit makes an untextured scene textured (everything).
  // A triangle's record only flags it as an emitter (its power per area is its material's): with
  // the same list, none changes; else those joining or leaving it (the symmetric difference of old
  // and new, both ascending as the lighting scene lists them; sorted here when not).
  std::vector<uint32_t> changed;
  if (edited.emitter_triangles != emitters_) {
    std::vector<uint32_t> before = emitters_, now = edited.emitter_triangles;
    std::sort(before.begin(), before.end());
    std::sort(now.begin(), now.end());
    std::set_symmetric_difference(before.begin(), before.end(), now.begin(), now.end(), std::back_inserter(changed));
    changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
  }
  emitters = at_least_one(edited.emitter_triangles);
  const bool whole_surfaces = surfaces_.size() == 0 || (edited.textured && !surfaces_textured_);
  surfaces = whole_surfaces ? surface_words(edited, surface_layout_) : material_surface_words(*edited.source, surface_layout_);
  grow(emitter_cdf_, edited.emitter_cdf.size() * sizeof(double));
  grow(emitter_triangles_, emitters.size() * 4);
  grow(surfaces_, surfaces.size() * sizeof(Vec4));
  using Write = Context::RangeWrite;
  writes.push_back(Write::whole(materials_, edited.materials.data(), edited.materials.size() * sizeof(GpuMaterial)));
  writes.push_back(Write::mirrored(triangles_, edited.triangles.data(), triangle_ranges(changed)));
  writes.push_back(Write::whole(emitter_cdf_, edited.emitter_cdf.data(), edited.emitter_cdf.size() * sizeof(double)));
  writes.push_back(Write::whole(emitter_triangles_, emitters.data(), emitters.size() * 4));
  writes.push_back(Write::whole(surfaces_, surfaces.data(), surfaces.size() * sizeof(Vec4)));
}

void GpuScene::materials_uploaded(const LightingScene& edited) {
  emitters_ = edited.emitter_triangles;
  emitter_inverse_power_ = edited.emitter_inverse_power;
  surface_flags_ = vulkan::surface_flags(edited);
  surfaces_textured_ = surfaces_textured_ || edited.textured;
}

void GpuScene::update_geometry(const LightingScene& edited) {
  check_same_shape(edited);
  if (edited.bvh.leaf_triangles.size() != leaf_slots_ || std::max<uint32_t>(edited.bvh.stack_entries + 1, 8) > stack_bound_)
    throw std::invalid_argument("Vulkan backend: a geometry update must keep the BVH's topology (refit_bvh4); "
                                "a rebuilt BVH needs a new integrator");
  check_supported_by_vulkan(edited);
  const std::vector<uint32_t> words = node_words(edited.bvh, quantized_);
  context_.upload(nodes_, words.data(), words.size() * 4);
  const std::vector<Vec4> leaf = leaf_triangle_copies(edited);
  context_.upload(leaf_triangles_, leaf.data(), leaf.size() * sizeof(Vec4));
  if (!edited.triangles.empty()) context_.upload(triangles_, edited.triangles.data(), edited.triangles.size() * sizeof(GpuTriangle));
  update_materials(edited);  // emitter areas and CDF follow the triangles
  update_lights(edited);     // directional powers follow the bounds
  bounds_lo_ = edited.bounds_lo;
  bounds_hi_ = edited.bounds_hi;
  extent_ = edited.extent;
}

void GpuScene::update_lights(const LightingScene& edited) {
  update_punctual_lights(edited);
  sky_ = edited.sky;
  update_environment(edited);
}

std::vector<Context::RangeWrite> GpuScene::punctual_writes(const LightingScene& edited) const {
  using Write = Context::RangeWrite;
  std::vector<Write> writes;
  if (punctual_count_ > 0)
    writes.push_back(Write::whole(punctual_lights_, edited.punctual_lights.data(), edited.punctual_lights.size() * sizeof(GpuPunctualLight)));
  writes.push_back(Write::whole(punctual_cdf_, edited.punctual_cdf.data(), edited.punctual_cdf.size() * sizeof(double)));
  return writes;
}

void GpuScene::update_moved_geometry(const LightingScene& edited, const Bvh4Links& links,
                                     const std::vector<uint32_t>& moved_triangles, const std::vector<uint32_t>& changed_nodes,
                                     bool emitters_changed, bool materials_changed) {
  check_same_shape(edited);
  check_supported_by_vulkan(edited);
  if (links.triangle_slot_start.size() != edited.triangles.size() + 1 || links.slot_leaf.size() != leaf_slots_)
    throw std::invalid_argument("Vulkan backend: the BVH links are not this scene's");
  for (size_t k = 0; k < moved_triangles.size(); ++k)
    if (moved_triangles[k] >= edited.triangles.size() || (k > 0 && moved_triangles[k] <= moved_triangles[k - 1]))
      throw std::invalid_argument("Vulkan backend: moved triangles must ascend within the scene");
  for (uint32_t n : changed_nodes)
    if (n >= node_count_) throw std::invalid_argument("Vulkan backend: BVH node " + std::to_string(n) + " of " + std::to_string(node_count_));
  // The changed nodes (in this scene's node layout), the moved triangles' leaf-slot vertex copies
  // and records, and the punctual lights and CDF (directional powers follow the bounds; moved
  // lights), in one submission.
  const size_t node_bytes = quantized_ ? kQuantizedNodeWords * 4 : sizeof(Bvh4Node);
  const std::vector<std::pair<uint32_t, uint32_t>> node_runs = record_runs(changed_nodes, node_bytes);
  std::vector<Bvh4Node> nodes;
  for (const auto& [first, end] : node_runs) nodes.insert(nodes.end(), edited.bvh.nodes.begin() + first, edited.bvh.nodes.begin() + end);
  const std::vector<uint32_t> words = node_words(Bvh4{nodes, {}, 1, 0}, quantized_);
  std::vector<Context::RangeWrite> writes;
  writes.push_back({&nodes_, byte_ranges(node_runs, node_bytes), [&](char* staging) { std::memcpy(staging, words.data(), words.size() * 4); }});
  std::vector<uint32_t> slots;
  for (uint32_t t : moved_triangles)
    for (uint32_t k = links.triangle_slot_start[t]; k < links.triangle_slot_start[size_t(t) + 1]; ++k) slots.push_back(links.triangle_slots[k]);
  std::sort(slots.begin(), slots.end());
  constexpr size_t kSlotBytes = 3 * sizeof(Vec4);
  const std::vector<std::pair<uint32_t, uint32_t>> slot_runs = record_runs(slots, kSlotBytes);
  writes.push_back({&leaf_triangles_, byte_ranges(slot_runs, kSlotBytes), [&](char* staging) {
                      for (const auto& [first, end] : slot_runs)
                        for (uint32_t s = first; s < end; ++s, staging += kSlotBytes) {
                          Vec4 copy[3];
                          leaf_triangle_copy(edited, s, copy);
                          std::memcpy(staging, copy, kSlotBytes);
                        }
                    }});
  writes.push_back(Context::RangeWrite::mirrored(triangles_, edited.triangles.data(), triangle_ranges(moved_triangles)));
  for (Context::RangeWrite& w : punctual_writes(edited)) writes.push_back(std::move(w));
  std::vector<Vec4> surfaces;
  std::vector<uint32_t> emitters;
  // Moved emitters keep their list (their records are among the moved ones above): their areas
  // change the CDF and the total alone. A changed list (an emitter whose area fell to 0, or back)
  // or edited materials: what update_materials writes.
  const bool whole_materials = materials_changed || (emitters_changed && edited.emitter_triangles != emitters_);
  if (whole_materials)
    add_material_writes(edited, writes, surfaces, emitters);
  else if (emitters_changed)
    writes.push_back(Context::RangeWrite::whole(emitter_cdf_, edited.emitter_cdf.data(), edited.emitter_cdf.size() * sizeof(double)));
  // Waited for here, on the edit's upload thread, while the caller's thread works on the texels
  // (recorded at the start of the publish instead, the copies lengthened the publish's wait by
  // 0.5-0.8 ms on an H100 host: bench/results/refresh-gpu.md).
  context_.write_ranges(writes);
  if (whole_materials) materials_uploaded(edited);
  else if (emitters_changed) emitter_inverse_power_ = edited.emitter_inverse_power;
  bounds_lo_ = edited.bounds_lo;
  bounds_hi_ = edited.bounds_hi;
  extent_ = edited.extent;
}

void GpuScene::set_changed_light_pairs(const LightingScene& edited, const std::vector<GpuPunctualLight>& pairs) {
  check_same_shape(edited);
  check_supported_by_vulkan(edited);
  std::vector<GpuPunctualLight> records = edited.punctual_lights;
  records.insert(records.end(), pairs.begin(), pairs.end());
  if (!records.empty()) {
    grow(punctual_lights_, records.size() * sizeof(GpuPunctualLight));  // room for kMaxChangedLightPairs from the start
    context_.upload_at_next_submission(punctual_lights_, records.data(), records.size() * sizeof(GpuPunctualLight));
  }
  // Both copied at the start of the next submission (the first samples of the change estimate):
  // a light edit waits for no upload of its own.
  context_.upload_at_next_submission(punctual_cdf_, edited.punctual_cdf.data(), edited.punctual_cdf.size() * sizeof(double));
}

void GpuScene::update_punctual_lights(const LightingScene& edited) {
  check_same_shape(edited);
  check_supported_by_vulkan(edited);
  context_.write_ranges_at_next_submission(punctual_writes(edited));  // at the start of the next submission, as set_changed_light_pairs
}

void GpuScene::update_environment(const LightingScene& edited) {
  const uint32_t width = edited.environment.enabled() ? edited.environment.width() : 0;
  const uint32_t height = edited.environment.enabled() ? edited.environment.height() : 0;
  // The EnvironmentSampler was rebuilt from the edited sky (lighting_scene_refresh.cpp), so an
  // image of the same size may still hold other texels: upload whenever there is an image.
  if (width > 0) {
    const std::vector<double> words = environment_words(edited);
    upload_growing(environment_, words.data(), words.size() * sizeof(double));
  }
  environment_width_ = width;
  environment_height_ = height;
}

}  // namespace exitance::vulkan
