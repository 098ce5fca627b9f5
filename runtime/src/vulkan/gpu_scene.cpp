#include "gpu_scene.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>
#include <string>

#include "bvh_quantization.h"
#include "gpu_surfaces.h"
#include "exitance/common/environment_map.h"
#include "exitance/runtime/core/scene_access.h"

namespace exitance::vulkan {
namespace {

static_assert(sizeof(GpuTriangle) == 96 && sizeof(GpuMaterial) == 32 && sizeof(GpuPunctualLight) == 48);

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

std::vector<uint32_t> node_words(const Bvh4& bvh, bool quantized) {
  if (quantized) return quantize_bvh4_nodes(bvh.nodes);
  std::vector<uint32_t> words(bvh.nodes.size() * sizeof(Bvh4Node) / 4);
  std::memcpy(words.data(), bvh.nodes.data(), words.size() * 4);
  return words;
}

// Per leaf slot, its triangle's vertices (and index, in the first w) where traversal reads them together.
std::vector<Vec4> leaf_triangle_copies(const LightingScene& scene) {
  std::vector<Vec4> leaf(std::max<size_t>(scene.bvh.leaf_triangles.size(), 1) * 3);
  for (size_t slot = 0; slot < scene.bvh.leaf_triangles.size(); ++slot) {
    const uint32_t t = scene.bvh.leaf_triangles[slot];
    leaf[slot * 3] = Vec4(scene_triangle_vertex(scene, t, 0), uintBitsToFloat(t));
    leaf[slot * 3 + 1] = Vec4(scene_triangle_vertex(scene, t, 1), 0.0f);
    leaf[slot * 3 + 2] = Vec4(scene_triangle_vertex(scene, t, 2), 0.0f);
  }
  return leaf;
}

// The records of `triangles` (sorted, unique) as byte ranges, consecutive ones merged.
std::vector<ByteRange> triangle_ranges(const std::vector<uint32_t>& triangles) {
  std::vector<ByteRange> ranges;
  for (uint32_t t : triangles) {
    const VkDeviceSize offset = VkDeviceSize(t) * sizeof(GpuTriangle);
    if (!ranges.empty() && ranges.back().offset + ranges.back().size == offset) ranges.back().size += sizeof(GpuTriangle);
    else ranges.push_back({offset, sizeof(GpuTriangle)});
  }
  return ranges;
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
      punctual_lights_(upload_new(context, at_least_one(scene.punctual_lights))),
      punctual_cdf_(upload_new(context, scene.punctual_cdf)),
      environment_(upload_new(context, environment_words(scene))),
      emitters_(scene.emitter_triangles),
      triangle_count_(scene.triangles.size()),
      material_count_(scene.materials.size()),
      punctual_count_(scene.punctual_count()),
      sky_(scene.sky),
      bounds_lo_(scene.bounds_lo),
      bounds_hi_(scene.bounds_hi),
      extent_(scene.extent),
      environment_width_(scene.environment.enabled() ? scene.environment.width() : 0),
      environment_height_(scene.environment.enabled() ? scene.environment.height() : 0),
      stack_bound_(std::max<uint32_t>(scene.bvh.stack_entries + 1, 8)),
      node_count_(uint32_t(scene.bvh.nodes.size())),
      leaf_slots_(uint32_t(scene.bvh.leaf_triangles.size())),
      quantized_(quantized_nodes) {
  upload_surfaces(scene);
}

void GpuScene::upload_surfaces(const LightingScene& scene) {
  surface_flags_ = vulkan::surface_flags(scene);
  // Textures and corners exist only in textured scenes; a material edit cannot change them, so it
  // uploads the header and the material records alone. An edit that makes an untextured scene
  // textured uploads everything (the buffer grows; the integrator binds it again before each bake).
  if (surfaces_.size() == 0 || (scene.textured && !surfaces_textured_)) {
    const std::vector<Vec4> words = surface_words(scene, surface_layout_);
    upload_growing(surfaces_, words.data(), words.size() * sizeof(Vec4));
    surfaces_textured_ = scene.textured;
    return;
  }
  const std::vector<Vec4> words = material_surface_words(*scene.source, surface_layout_);
  context_.upload(surfaces_, words.data(), words.size() * sizeof(Vec4));
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
  if (bytes > buffer.size()) buffer = context_.create_storage_buffer(bytes);
  context_.upload(buffer, data, bytes);
}

void GpuScene::update_materials(const LightingScene& edited) {
  check_same_shape(edited);
  check_supported_by_vulkan(edited);
  if (!edited.materials.empty()) context_.upload(materials_, edited.materials.data(), edited.materials.size() * sizeof(GpuMaterial));
  std::vector<uint32_t> changed = emitters_;
  changed.insert(changed.end(), edited.emitter_triangles.begin(), edited.emitter_triangles.end());
  std::sort(changed.begin(), changed.end());
  changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
  context_.upload_ranges(triangles_, edited.triangles.data(), triangle_ranges(changed));
  upload_growing(emitter_cdf_, edited.emitter_cdf.data(), edited.emitter_cdf.size() * sizeof(double));
  const std::vector<uint32_t> emitters = at_least_one(edited.emitter_triangles);
  upload_growing(emitter_triangles_, emitters.data(), emitters.size() * 4);
  emitters_ = edited.emitter_triangles;
  upload_surfaces(edited);
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
  check_same_shape(edited);
  check_supported_by_vulkan(edited);
  if (punctual_count_ > 0)
    context_.upload(punctual_lights_, edited.punctual_lights.data(), edited.punctual_lights.size() * sizeof(GpuPunctualLight));
  context_.upload(punctual_cdf_, edited.punctual_cdf.data(), edited.punctual_cdf.size() * sizeof(double));
  sky_ = edited.sky;
  update_environment(edited);
}

void GpuScene::set_changed_light_pairs(const LightingScene& edited, const std::vector<GpuPunctualLight>& pairs) {
  check_same_shape(edited);
  std::vector<GpuPunctualLight> records = edited.punctual_lights;
  records.insert(records.end(), pairs.begin(), pairs.end());
  if (!records.empty()) upload_growing(punctual_lights_, records.data(), records.size() * sizeof(GpuPunctualLight));
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
