#include "exitance/bake/cache/bake_cache_key.h"

#include <filesystem>

#include "exitance/bake/cache/scene_hashing.h"
#include "exitance/bake/cache/sha256_stream.h"

namespace exitance {
namespace {

// A new field in one of these must be added to the key below; the sizes catch most additions.
// Not hashed: work_share (how many processes lit a bake does not change its bits: issue 15),
// guiding_octree (the bake's own octree, from the hashed voxel options), the inspect callbacks,
// budget_clock (the time budget's clock; the budget itself is hashed) and bounce_caches_on_host
// (where the per-bounce caches are built: the same pages bit for bit).
static_assert(sizeof(IntegratorSettings) == 336, "IntegratorSettings changed: hash the new field in bake_cache_key");
static_assert(sizeof(AtlasSettings) == 24, "AtlasSettings changed: hash the new field in bake_cache_key");
// Not hashed: input and output paths (the input's name and bytes are), cache_directory and
// write_gltf (where results go does not change them), progress.
static_assert(sizeof(BakeOptions) == 640, "BakeOptions changed: hash the new field in bake_cache_key (or say why not)");
static_assert(sizeof(ImportOptions) == 8, "ImportOptions changed: hash the new field in bake_cache_key");
static_assert(sizeof(Material) == 168, "Material changed: hash the new field in bake_cache_key");
static_assert(sizeof(PunctualLight) == 88, "PunctualLight changed: hash the new field in bake_cache_key");

using scene_hashing::binding;
using scene_hashing::vec3;

void hash_scene(Sha256Stream& h, const Scene& scene) {
  h.array(scene.positions), h.array(scene.normals), h.array(scene.uv0), h.array(scene.lightmap_uv);
  h.array(scene.vertex_color), h.array(scene.vertex_alpha), h.array(scene.tangents), h.array(scene.tangent_signs);
  h.array(scene.triangle_material), h.array(scene.triangle_instance);
  h.value(uint64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    h.text(m.name);
    vec3(h, m.base_color), binding(h, m.base_color_texture), h.value(m.metallic);
    vec3(h, m.emission), binding(h, m.emissive_texture), h.value(m.double_sided);
    h.value(m.alpha_mode), h.value(m.alpha_cutoff), h.value(m.base_alpha);
    binding(h, m.normal_texture), h.value(m.normal_scale);
  }
  h.value(uint64_t(scene.textures.size()));
  for (const Texture& t : scene.textures) scene_hashing::texture(h, t);
  h.value(uint64_t(scene.instances.size()));
  for (const Instance& i : scene.instances) {
    h.value(i.node), h.text(i.name), h.value(i.mesh), h.value(i.first_triangle), h.value(i.triangle_count);
    h.bytes(i.world.data(), sizeof i.world);
  }
  h.value(uint64_t(scene.lights.size()));
  for (const PunctualLight& l : scene.lights) {
    h.value(l.type), h.text(l.name), vec3(h, l.position), vec3(h, l.direction), vec3(h, l.intensity);
    h.value(l.cos_inner), h.value(l.cos_outer), h.value(l.node);
  }
  vec3(h, scene.sky.constant), scene_hashing::texture(h, scene.sky.environment);
  h.value(uint64_t(scene.nodes.size()));
  for (const SceneNode& n : scene.nodes) {
    h.text(n.name), h.value(n.parent), h.value(n.mesh), h.value(n.light), h.value(n.camera), h.value(n.in_scene);
    h.value(n.has_matrix);
    h.bytes(n.translation.data(), sizeof n.translation), h.bytes(n.rotation.data(), sizeof n.rotation);
    h.bytes(n.scale.data(), sizeof n.scale), h.bytes(n.matrix.data(), sizeof n.matrix);
  }
  h.value(uint64_t(scene.cameras.size()));
  for (const SceneCamera& c : scene.cameras) {
    h.text(c.name), h.value(c.node), h.value(c.type), h.value(c.yfov), h.value(c.aspect_ratio), h.value(c.xmag);
    h.value(c.ymag), h.value(c.znear), h.value(c.zfar);
  }
}

void hash_options(Sha256Stream& h, const BakeOptions& o) {
  h.text(o.sky), h.text(o.backend.name), h.value(o.backend.device_index), h.value(o.backend.validation);
  h.value(o.import.lightmap_uv_set), h.value(o.import.generate_lightmap_uvs);
  h.value(o.atlas.texel_density), h.value(o.atlas.max_page), h.value(o.atlas.padding);
  h.value(uint64_t(o.atlas.max_total_texels));
  const IntegratorSettings& l = o.lighting;
  h.value(l.integrator), h.value(l.spp), h.value(l.time_budget_seconds), h.value(l.target_relative_error);
  h.value(l.max_bounces), h.value(l.seed), h.value(l.recorded_bounces), h.value(l.russian_roulette_start);
  h.value(l.safety_bounce_cap), h.value(l.sampling_strategy), h.value(l.sampler), h.value(l.guiding), h.value(l.guiding_mix);
  h.value(l.trace_first_bounce), h.value(l.light_layers);
  h.value(o.integrator_auto), h.value(o.emitter_guiding_auto), h.value(o.guiding_auto_given);
  h.value(l.directional);
  h.value(l.guiding_grid_cells), h.value(l.adaptive), h.value(o.adaptive_request);
  h.value(l.guiding_svo_c_ray), h.value(l.guiding_svo_rays_per_bin), h.value(l.guiding_svo_emitted);
  h.value(l.guiding_svo_texels);
  h.value(l.emitter_guiding), h.value(l.emitter_guiding_mix), h.value(l.emitter_guiding_patches);
  h.value(l.light_subpaths), h.value(l.light_subpaths_per_sample), h.value(l.guiding_auto_candidate);
  h.value(o.bounce_layers), h.value(o.probes_enabled), h.value(o.probe_spacing), h.value(o.probe_spp);
  h.value(o.probe_sh_window), h.value(o.svo_enabled), h.value(o.voxel_resolution);
  h.value(o.skip_sealed_texels), h.value(o.stitch_seams), h.value(o.denoise), h.value(o.denoise_radius);
  h.value(o.preview), h.value(o.preview_size);
}

}  // namespace

const std::string& program_identity() {
  static const std::string identity = [] {
    try {
      return sha256_of_file(std::filesystem::read_symlink("/proc/self/exe").string());
    } catch (...) {
      return std::string();
    }
  }();
  return identity;
}

std::string bake_cache_key(const Scene& scene, const BakeOptions& options, const std::string& input_sha256,
                           const std::string& devices) {
  Sha256Stream h;
  h.text("exitance bake cache key, version 1");
  h.text(program_identity());
  h.text(devices);
  h.text(std::filesystem::path(options.input).filename().string());
  h.text(input_sha256);
  hash_scene(h, scene);
  hash_options(h, options);
  return h.hex();
}

}  // namespace exitance
