// A self-contained dump of what the Vulkan backend needs for one bake: the lighting stage's scene
// (triangles, materials, lights, constant sky), the live texels' G-buffer and the GPU BVH as built
// here by Embree. bench_vulkan_throughput --write-replay writes it; bench_vulkan_replay (built by
// bench/vulkan/build_replay.sh with no dependency but the Vulkan loader) replays it on a machine
// that has no Embree, TBB, tinygltf or OpenImageIO, e.g. the GPU machine.
//
// Little-endian, host layout: magic "EXRPLAY2", then length-prefixed sections (see write_replay).
// BVH leaves are stored as scene triangle ids; the replay rebuilds the leaf vertices from the scene.
#pragma once
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"
#include "exitance/runtime/core/bvh4.h"

namespace exitance::replay {

struct ReplayInfo {
  std::string scene_name;
  float texel_density = 0;
};

namespace detail {
struct Writer {
  std::FILE* f;
  void raw(const void* p, size_t n) {
    if (n && std::fwrite(p, 1, n, f) != n) throw std::runtime_error("replay: write failed");
  }
  template <typename T> void pod(const T& v) { raw(&v, sizeof(T)); }
  template <typename T> void vec(const std::vector<T>& v) {
    pod(uint64_t(v.size()));
    raw(v.data(), v.size() * sizeof(T));
  }
};
struct Reader {
  std::FILE* f;
  void raw(void* p, size_t n) {
    if (n && std::fread(p, 1, n, f) != n) throw std::runtime_error("replay: truncated file");
  }
  template <typename T> T pod() { T v; raw(&v, sizeof(T)); return v; }
  template <typename T> std::vector<T> vec() {
    const uint64_t n = pod<uint64_t>();
    if (n > (uint64_t(1) << 34) / sizeof(T)) throw std::runtime_error("replay: implausible section size");
    std::vector<T> v(n);
    raw(v.data(), n * sizeof(T));
    return v;
  }
};
constexpr char kMagic[8] = {'E', 'X', 'R', 'P', 'L', 'A', 'Y', '2'};
}  // namespace detail

inline void write_replay(const std::string& path, const ReplayInfo& info, const Scene& scene,
                         const TexelGBuffer& gbuffer, const Bvh4& bvh) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw std::runtime_error("replay: cannot write " + path);
  detail::Writer w{f};
  w.raw(detail::kMagic, 8);
  w.vec(std::vector<char>(info.scene_name.begin(), info.scene_name.end()));
  w.pod(info.texel_density);
  w.vec(scene.positions);
  w.vec(scene.normals);
  w.vec(scene.triangle_material);
  w.pod(uint64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    w.pod(m.base_color), w.pod(m.metallic), w.pod(m.emission), w.pod(uint32_t(m.double_sided));
    w.pod(int32_t(m.base_color_texture.texture)), w.pod(int32_t(m.emissive_texture.texture));
  }
  w.pod(uint64_t(scene.lights.size()));
  for (const PunctualLight& l : scene.lights) {
    w.pod(uint32_t(l.type)), w.pod(l.position), w.pod(l.direction), w.pod(l.intensity);
    w.pod(l.cos_inner), w.pod(l.cos_outer);
  }
  w.pod(scene.sky.constant);
  std::vector<float> texels(gbuffer.texels.size() * 9);
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const LiveTexel& t = gbuffer.texels[i];
    const Vec3 v[3] = {t.position, t.geometric_normal, t.shading_normal};
    for (int k = 0; k < 3; ++k) texels[i * 9 + size_t(3 * k)] = v[k].x, texels[i * 9 + size_t(3 * k + 1)] = v[k].y,
                                texels[i * 9 + size_t(3 * k + 2)] = v[k].z;
  }
  w.vec(texels);
  w.vec(bvh.nodes);
  const std::vector<uint32_t>& leaf_ids = bvh.leaf_triangles;
  w.vec(leaf_ids);
  w.pod(bvh.stack_entries), w.pod(bvh.depth);
  std::fclose(f);
}

inline void read_replay(const std::string& path, ReplayInfo& info, Scene& scene, TexelGBuffer& gbuffer,
                        Bvh4& bvh) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw std::runtime_error("replay: cannot read " + path);
  detail::Reader r{f};
  char magic[8];
  r.raw(magic, 8);
  if (std::memcmp(magic, detail::kMagic, 8) != 0) throw std::runtime_error("replay: not a replay file: " + path);
  const std::vector<char> name = r.vec<char>();
  info.scene_name.assign(name.begin(), name.end());
  info.texel_density = r.pod<float>();
  scene.positions = r.vec<Vec3>();
  scene.normals = r.vec<Vec3>();
  scene.triangle_material = r.vec<uint32_t>();
  scene.materials.resize(r.pod<uint64_t>());
  for (Material& m : scene.materials) {
    m.base_color = r.pod<Vec3>(), m.metallic = r.pod<float>(), m.emission = r.pod<Vec3>();
    m.double_sided = r.pod<uint32_t>() != 0;
    m.base_color_texture.texture = r.pod<int32_t>(), m.emissive_texture.texture = r.pod<int32_t>();
  }
  scene.lights.resize(r.pod<uint64_t>());
  for (PunctualLight& l : scene.lights) {
    l.type = PunctualLight::Type(r.pod<uint32_t>());
    l.position = r.pod<Vec3>(), l.direction = r.pod<Vec3>(), l.intensity = r.pod<Vec3>();
    l.cos_inner = r.pod<float>(), l.cos_outer = r.pod<float>();
  }
  scene.sky.constant = r.pod<Vec3>();
  const std::vector<float> texels = r.vec<float>();
  gbuffer.texels.resize(texels.size() / 9);
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    LiveTexel& t = gbuffer.texels[i];
    const float* v = &texels[i * 9];
    t.position = {v[0], v[1], v[2]}, t.geometric_normal = {v[3], v[4], v[5]}, t.shading_normal = {v[6], v[7], v[8]};
  }
  bvh.nodes = r.vec<Bvh4Node>();
  bvh.leaf_triangles = r.vec<uint32_t>();
  for (uint32_t t : bvh.leaf_triangles)
    if (size_t(t) * 3 + 2 >= scene.positions.size()) throw std::runtime_error("replay: leaf triangle out of range");
  bvh.stack_entries = r.pod<uint32_t>();
  bvh.depth = r.pod<uint32_t>();
  std::fclose(f);
}

}  // namespace exitance::replay
