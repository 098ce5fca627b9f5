#include "exitance/bake/cache/stage_cache_keys.h"

#include "exitance/bake/cache/scene_hashing.h"
#include "exitance/bake/cache/sha256_stream.h"

namespace exitance {
namespace {

// A new field in one of these must be sorted into the keys below (or said to be lighting-only).
// normal_texture / normal_scale (and Scene::tangents): no offline stage reads them; only scene.bin
// and exitance-view do, and the bundle cache key hashes them.
static_assert(sizeof(Material) == 168, "Material changed: hash the new field in stage_cache_keys where a stage reads it");
static_assert(sizeof(PunctualLight) == 88, "PunctualLight changed: hash the new field in stage_cache_keys if a stage reads it");
static_assert(sizeof(AtlasSettings) == 24, "AtlasSettings changed: hash the new field in the layout key");

constexpr const char* kKeyVersion = "exitance stage cache key, version 1";

void begin(Sha256Stream& h, const char* stage, const BakeOptions& options, const std::string& program) {
  h.text(kKeyVersion), h.text(stage), h.text(program), h.text(options.input);
}

void geometry(Sha256Stream& h, const Scene& scene) {
  h.array(scene.positions), h.array(scene.lightmap_uv), h.array(scene.triangle_instance);
  h.value(uint64_t(scene.instances.size()));
  for (const Instance& i : scene.instances) {
    h.value(i.node), h.text(i.name), h.value(i.mesh), h.value(i.first_triangle), h.value(i.triangle_count);
    h.bytes(i.world.data(), sizeof i.world);
  }
}

void textures(Sha256Stream& h, const Scene& scene) {
  h.value(uint64_t(scene.textures.size()));
  for (const Texture& t : scene.textures) scene_hashing::texture(h, t);
}

void albedo(Sha256Stream& h, const Scene& scene) {
  h.array(scene.triangle_material), h.array(scene.uv0), h.array(scene.lightmap_uv), h.array(scene.vertex_color);
  h.value(uint64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    scene_hashing::vec3(h, m.base_color), scene_hashing::binding(h, m.base_color_texture), h.value(m.metallic);
  }
  textures(h, scene);
}

void visibility(Sha256Stream& h, const Scene& scene) {
  // The alpha texture may be read through either UV set (its binding's tex_coord).
  h.array(scene.triangle_material), h.array(scene.uv0), h.array(scene.lightmap_uv), h.array(scene.vertex_alpha);
  h.value(uint64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    h.value(m.double_sided), h.value(m.alpha_mode), h.value(m.alpha_cutoff), h.value(m.base_alpha);
    scene_hashing::binding(h, m.base_color_texture);
  }
  textures(h, scene);
}

// Where the punctual lights are (not how bright): what the checks and sealed texels trace towards.
void light_placement(Sha256Stream& h, const Scene& scene) {
  h.value(uint64_t(scene.lights.size()));
  for (const PunctualLight& l : scene.lights) {
    h.value(l.type), h.text(l.name), scene_hashing::vec3(h, l.position), scene_hashing::vec3(h, l.direction);
  }
}

// Which triangles emit at all (the checks count zero-area emitters), not how much.
void emissive_triangles(Sha256Stream& h, const Scene& scene) {
  std::vector<uint8_t> emissive(scene.triangle_count(), 0);
  for (size_t t = 0; t < emissive.size(); ++t) {
    const Vec3 e = scene.materials[scene.triangle_material[t]].emission;
    emissive[t] = (e.x > 0 || e.y > 0 || e.z > 0) ? 1 : 0;
  }
  h.array(emissive);
}

}  // namespace

StageCacheKeys stage_cache_keys(const Scene& scene, const BakeOptions& options, const std::string& program) {
  StageCacheKeys keys;
  {
    Sha256Stream h;
    begin(h, "layout", options, program);
    geometry(h, scene);
    h.value(options.atlas.texel_density), h.value(options.atlas.max_page), h.value(options.atlas.padding);
    h.value(uint64_t(options.atlas.max_total_texels));
    keys.layout = h.hex();
  }
  {
    Sha256Stream h;
    begin(h, "gbuffer", options, program);
    h.text(keys.layout), h.array(scene.normals);
    albedo(h, scene), visibility(h, scene);
    keys.gbuffer = h.hex();
  }
  {
    Sha256Stream h;
    begin(h, "checks", options, program);
    h.text(keys.gbuffer), visibility(h, scene), light_placement(h, scene), emissive_triangles(h, scene);
    keys.checks = h.hex();
  }
  {
    Sha256Stream h;
    begin(h, "sealed_texels", options, program);
    h.text(keys.gbuffer), visibility(h, scene), light_placement(h, scene);
    keys.sealed_texels = h.hex();
  }
  {
    Sha256Stream h;
    begin(h, "voxelize", options, program);
    h.text(keys.layout), h.array(scene.positions), h.value(options.voxel_resolution);
    keys.voxelize = h.hex();
  }
  {
    Sha256Stream h;
    begin(h, "probe_placement", options, program);
    geometry(h, scene), visibility(h, scene);
    h.text(options.svo_enabled ? keys.voxelize : std::string("no octree"));
    h.value(options.probe_spacing);
    keys.probe_placement = h.hex();
  }
  return keys;
}

}  // namespace exitance
