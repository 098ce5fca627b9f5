#include "exitance/runtime/scene_file_conversion.h"

#include <cstring>

#include <string>

#include "exitance/formats/huge_pages.h"
#include "exitance/runtime/texel_gbuffer_codec.h"

namespace exitance {
namespace {

using formats::FormatError;

formats::Float3 to_record(Vec3 v) { return {v.x, v.y, v.z}; }
formats::Float2 to_record(Vec2 v) { return {v.x, v.y}; }
Vec3 from_record(const formats::Float3& v) { return {v[0], v[1], v[2]}; }
Vec2 from_record(const formats::Float2& v) { return {v[0], v[1]}; }

formats::TextureRecord to_record(const Texture& t, const std::string& what) {
  if (t.width < 0 || t.height < 0)
    throw FormatError("scene.bin (writing): " + what + ": size " + std::to_string(t.width) + " x " +
                      std::to_string(t.height) + " is negative");
  formats::TextureRecord r;
  r.width = uint32_t(t.width);
  r.height = uint32_t(t.height);
  r.wrap_s = formats::TextureWrap(uint32_t(t.wrap_s));
  r.wrap_t = formats::TextureWrap(uint32_t(t.wrap_t));
  r.rgb = t.rgb;
  r.alpha = t.alpha;
  return r;
}
Texture from_record(const formats::TextureRecord& r) {
  Texture t;
  t.width = int(r.width);
  t.height = int(r.height);
  t.wrap_s = Texture::Wrap(uint32_t(r.wrap_s));
  t.wrap_t = Texture::Wrap(uint32_t(r.wrap_t));
  t.rgb = r.rgb;
  t.alpha = r.alpha;
  return t;
}
static_assert(uint32_t(Texture::Wrap::Repeat) == uint32_t(formats::TextureWrap::Repeat) &&
              uint32_t(Texture::Wrap::ClampToEdge) == uint32_t(formats::TextureWrap::ClampToEdge) &&
              uint32_t(Texture::Wrap::MirroredRepeat) == uint32_t(formats::TextureWrap::MirroredRepeat));
static_assert(uint32_t(Material::AlphaMode::Opaque) == uint32_t(formats::AlphaMode::Opaque) &&
              uint32_t(Material::AlphaMode::Mask) == uint32_t(formats::AlphaMode::Mask) &&
              uint32_t(Material::AlphaMode::Blend) == uint32_t(formats::AlphaMode::Blend));

formats::TextureBindingRecord to_record(const TextureBinding& b) {
  formats::TextureBindingRecord r;
  r.texture = b.texture < 0 ? -1 : b.texture;
  r.tex_coord = uint32_t(b.transform.tex_coord);  // validation refuses anything but 0 and 1
  r.offset = to_record(b.transform.offset);
  r.rotation = b.transform.rotation;
  r.scale = to_record(b.transform.scale);
  return r;
}
TextureBinding from_record(const formats::TextureBindingRecord& r) {
  TextureBinding b;
  b.texture = r.texture;
  b.transform.tex_coord = int(r.tex_coord);
  b.transform.offset = from_record(r.offset);
  b.transform.rotation = r.rotation;
  b.transform.scale = from_record(r.scale);
  return b;
}

uint32_t non_negative(int v, const std::string& what) {
  if (v < 0) throw FormatError("scene.bin (writing): " + what + " " + std::to_string(v) + " is negative");
  return uint32_t(v);
}

}  // namespace

formats::SceneFile make_scene_file(const Scene& scene, const TexelGBuffer& gbuffer, const AtlasLayout& atlas,
                                   const formats::ProbeGrid* probes, const formats::SceneBvh& bvh) {
  formats::SceneFile file;
  const size_t corners = scene.triangle_count() * 3;
  if (scene.positions.size() != corners || scene.normals.size() != corners || scene.uv0.size() != corners ||
      scene.lightmap_uv.size() != corners || scene.triangle_instance.size() != scene.triangle_count())
    throw FormatError("scene.bin (writing): the scene's per-corner arrays do not hold 3 entries per triangle");
  formats::SceneTriangles& t = file.triangles;
  t.positions.reserve(corners);
  t.normals.reserve(corners);
  t.lightmap_uv.reserve(corners);
  t.uv0.reserve(corners);
  for (size_t c = 0; c < corners; ++c) {
    t.positions.push_back(to_record(scene.positions[c]));
    t.normals.push_back(to_record(scene.normals[c]));
    t.lightmap_uv.push_back(to_record(scene.lightmap_uv[c]));
    t.uv0.push_back(to_record(scene.uv0[c]));
  }
  t.material = scene.triangle_material;
  t.instance = scene.triangle_instance;

  if (scene.vertex_color.size() != scene.vertex_alpha.size() ||
      (!scene.vertex_color.empty() && scene.vertex_color.size() != corners))
    throw FormatError("scene.bin (writing): COLOR_0: vertex colours and alphas do not hold one entry per corner");
  file.vertex_color.reserve(scene.vertex_color.size());
  for (const Vec3& c : scene.vertex_color) file.vertex_color.push_back(to_record(c));
  file.vertex_alpha = scene.vertex_alpha;
  if (scene.tangents.size() != scene.tangent_signs.size() || (!scene.tangents.empty() && scene.tangents.size() != corners))
    throw FormatError("scene.bin (writing): tangents and their signs do not hold one entry per corner");
  file.tangents.reserve(scene.tangents.size());
  for (const Vec3& v : scene.tangents) file.tangents.push_back(to_record(v));
  file.tangent_signs = scene.tangent_signs;
  for (size_t i = 0; i < scene.textures.size(); ++i)
    file.textures.push_back(to_record(scene.textures[i], "texture " + std::to_string(i)));
  for (const Material& m : scene.materials) {
    formats::MaterialRecord r;
    r.name = m.name;
    r.base_color = to_record(m.base_color);
    r.metallic = m.metallic;
    r.emission = to_record(m.emission);
    r.double_sided = m.double_sided;
    r.base_color_texture = to_record(m.base_color_texture);
    r.emissive_texture = to_record(m.emissive_texture);
    r.alpha_mode = formats::AlphaMode(uint32_t(m.alpha_mode));
    r.alpha_cutoff = m.alpha_cutoff;
    r.base_alpha = m.base_alpha;
    r.normal_texture = to_record(m.normal_texture);
    r.normal_scale = m.normal_scale;
    file.materials.push_back(std::move(r));
  }

  if (atlas.rects.size() != scene.instances.size())
    throw FormatError("scene.bin (writing): the atlas has " + std::to_string(atlas.rects.size()) + " rectangles for " +
                      std::to_string(scene.instances.size()) + " instances");
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& instance = scene.instances[i];
    const InstanceRect& rect = atlas.rects[i];
    const std::string what = "instance " + std::to_string(i) + " atlas";
    formats::InstanceRecord r;
    r.name = instance.name;
    r.node = instance.node;
    r.mesh = instance.mesh;
    r.first_triangle = instance.first_triangle;
    r.triangle_count = instance.triangle_count;
    r.world = instance.world;
    r.page = non_negative(rect.page, what + " page");
    r.x = non_negative(rect.x, what + " x");
    r.y = non_negative(rect.y, what + " y");
    r.width = non_negative(rect.width, what + " width");
    r.height = non_negative(rect.height, what + " height");
    for (int k = 0; k < 4; ++k) r.scale_offset[size_t(k)] = rect.scale_offset[k];
    file.instances.push_back(std::move(r));
  }

  for (const SceneNode& n : scene.nodes) {
    formats::NodeRecord r;
    r.name = n.name;
    r.parent = n.parent;
    r.mesh = n.mesh;
    r.light = n.light;
    r.camera = n.camera;
    r.in_scene = n.in_scene;
    r.has_matrix = n.has_matrix;
    r.translation = n.translation;
    r.rotation = n.rotation;
    r.scale = n.scale;
    r.matrix = n.matrix;
    file.nodes.push_back(std::move(r));
  }
  for (const SceneCamera& c : scene.cameras) {
    formats::CameraRecord r;
    r.name = c.name;
    r.node = c.node;
    r.type = c.type == SceneCamera::Type::Orthographic ? formats::CameraType::Orthographic
                                                       : formats::CameraType::Perspective;
    r.yfov = c.yfov, r.aspect_ratio = c.aspect_ratio, r.xmag = c.xmag, r.ymag = c.ymag, r.znear = c.znear,
    r.zfar = c.zfar;
    file.cameras.push_back(std::move(r));
  }
  for (const PunctualLight& l : scene.lights) {
    formats::LightRecord r;
    r.name = l.name;
    r.node = l.node;
    r.type = l.type == PunctualLight::Type::Spot          ? formats::LightType::Spot
             : l.type == PunctualLight::Type::Directional ? formats::LightType::Directional
                                                          : formats::LightType::Point;
    r.position = to_record(l.position);
    r.direction = to_record(l.direction);
    r.intensity = to_record(l.intensity);
    r.cos_inner = l.cos_inner;
    r.cos_outer = l.cos_outer;
    file.lights.push_back(std::move(r));
  }

  file.sky = to_record(scene.sky.constant);
  if (scene.sky.has_environment()) file.sky_environment = to_record(scene.sky.environment, "sky environment");
  file.texel_density = atlas.texel_density;

  if (atlas.page_sizes.size() != gbuffer.pages.size())
    throw FormatError("scene.bin (writing): the atlas has " + std::to_string(atlas.page_sizes.size()) +
                      " pages, the G-buffer " + std::to_string(gbuffer.pages.size()));
  for (size_t p = 0; p < gbuffer.pages.size(); ++p)
    if (atlas.page_sizes[p] != std::pair<int, int>{gbuffer.pages[p].width, gbuffer.pages[p].height})
      throw FormatError("scene.bin (writing): page " + std::to_string(p) + ": atlas and G-buffer sizes differ");
  file.texels = encode_texel_gbuffer(gbuffer, scene, atlas);

  if (probes) {
    file.probes = *probes;
    for (formats::ProbeRecord& r : file.probes.probes) r.sh = {};
  }
  file.bvh = bvh;
  return file;
}

PersistedScene restore_scene(const formats::SceneFile& file) {
  PersistedScene out;
  Scene& scene = out.scene;
  const formats::SceneTriangles& t = file.triangles;
  const size_t corners = t.positions.size();
  if (t.normals.size() != corners || t.lightmap_uv.size() != corners || t.uv0.size() != corners ||
      corners != 3 * t.material.size() || t.instance.size() != t.material.size())
    throw FormatError("scene.bin: triangle arrays disagree in length");
  // The large arrays in huge pages where the kernel allows: their first touch was most of a restore.
  formats::reserve_in_huge_pages(scene.positions, corners);
  formats::reserve_in_huge_pages(scene.normals, corners);
  formats::reserve_in_huge_pages(scene.lightmap_uv, corners);
  formats::reserve_in_huge_pages(scene.uv0, corners);
  for (size_t c = 0; c < corners; ++c) {
    scene.positions.push_back(from_record(t.positions[c]));
    scene.normals.push_back(from_record(t.normals[c]));
    scene.lightmap_uv.push_back(from_record(t.lightmap_uv[c]));
    scene.uv0.push_back(from_record(t.uv0[c]));
  }
  scene.triangle_material = formats::copy_in_huge_pages(t.material);
  scene.triangle_instance = formats::copy_in_huge_pages(t.instance);

  for (const formats::MaterialRecord& r : file.materials) {
    Material m;
    m.name = r.name;
    m.base_color = from_record(r.base_color);
    m.metallic = r.metallic;
    m.emission = from_record(r.emission);
    m.double_sided = r.double_sided;
    m.base_color_texture = from_record(r.base_color_texture);
    m.emissive_texture = from_record(r.emissive_texture);
    m.alpha_mode = Material::AlphaMode(uint32_t(r.alpha_mode));
    m.alpha_cutoff = r.alpha_cutoff;
    m.base_alpha = r.base_alpha;
    m.normal_texture = from_record(r.normal_texture);
    m.normal_scale = r.normal_scale;
    scene.materials.push_back(std::move(m));
  }
  for (const formats::TextureRecord& r : file.textures) scene.textures.push_back(from_record(r));
  scene.vertex_color.reserve(file.vertex_color.size());
  for (const formats::Float3& c : file.vertex_color) scene.vertex_color.push_back(from_record(c));
  scene.vertex_alpha = file.vertex_alpha;
  scene.tangents.reserve(file.tangents.size());
  for (const formats::Float3& v : file.tangents) scene.tangents.push_back(from_record(v));
  scene.tangent_signs = file.tangent_signs;
  out.atlas.texel_density = file.texel_density;
  for (const formats::TexelPageRecord& p : file.texels.pages)
    out.atlas.page_sizes.emplace_back(int(p.width), int(p.height));
  for (const formats::InstanceRecord& r : file.instances) {
    Instance instance;
    instance.name = r.name;
    instance.node = r.node;
    instance.mesh = r.mesh;
    instance.first_triangle = r.first_triangle;
    instance.triangle_count = r.triangle_count;
    instance.world = r.world;
    scene.instances.push_back(std::move(instance));
    InstanceRect rect;
    rect.page = int(r.page);
    rect.x = int(r.x), rect.y = int(r.y), rect.width = int(r.width), rect.height = int(r.height);
    for (int k = 0; k < 4; ++k) rect.scale_offset[k] = r.scale_offset[size_t(k)];
    out.atlas.rects.push_back(rect);
  }
  for (const formats::NodeRecord& r : file.nodes) {
    SceneNode n;
    n.name = r.name;
    n.parent = r.parent;
    n.mesh = r.mesh;
    n.light = r.light;
    n.camera = r.camera;
    n.in_scene = r.in_scene;
    n.has_matrix = r.has_matrix;
    n.translation = r.translation;
    n.rotation = r.rotation;
    n.scale = r.scale;
    n.matrix = r.matrix;
    scene.nodes.push_back(std::move(n));
  }
  for (const formats::CameraRecord& r : file.cameras) {
    SceneCamera c;
    c.name = r.name;
    c.node = r.node;
    c.type =
        r.type == formats::CameraType::Orthographic ? SceneCamera::Type::Orthographic : SceneCamera::Type::Perspective;
    c.yfov = r.yfov, c.aspect_ratio = r.aspect_ratio, c.xmag = r.xmag, c.ymag = r.ymag, c.znear = r.znear,
    c.zfar = r.zfar;
    scene.cameras.push_back(std::move(c));
  }
  for (const formats::LightRecord& r : file.lights) {
    PunctualLight l;
    l.name = r.name;
    l.node = r.node;
    l.type = r.type == formats::LightType::Spot          ? PunctualLight::Type::Spot
             : r.type == formats::LightType::Directional ? PunctualLight::Type::Directional
                                                         : PunctualLight::Type::Point;
    l.position = from_record(r.position);
    l.direction = from_record(r.direction);
    l.intensity = from_record(r.intensity);
    l.cos_inner = r.cos_inner;
    l.cos_outer = r.cos_outer;
    scene.lights.push_back(std::move(l));
  }
  scene.sky.constant = from_record(file.sky);
  if (file.sky_environment.width != 0) scene.sky.environment = from_record(file.sky_environment);

  out.gbuffer = decode_texel_gbuffer(file.texels, scene);
  out.gbuffer.instance_rects = out.atlas.rects;  // as the raster stage's G-buffer has them
  out.probes = file.probes;
  for (formats::ProbeRecord& r : out.probes.probes) r.sh = {};
  // Field by field, to copy the arrays into huge pages (the assert catches a field added later).
  static_assert(sizeof(formats::SceneBvh) == 2 * sizeof(std::vector<uint32_t>) + 2 * sizeof(uint32_t));
  out.bvh.nodes = formats::copy_in_huge_pages(file.bvh.nodes);
  out.bvh.leaf_triangles = formats::copy_in_huge_pages(file.bvh.leaf_triangles);
  out.bvh.stack_entries = file.bvh.stack_entries;
  out.bvh.depth = file.bvh.depth;
  return out;
}

static_assert(sizeof(Bvh4Node) == sizeof(formats::BvhNodeRecord));
static_assert(kBvhEmptyChild == formats::kSceneBvhEmptyChild && kBvhLeafBit == formats::kSceneBvhLeafBit);

formats::SceneBvh to_scene_bvh(const Bvh4& bvh) {
  formats::SceneBvh records;
  records.nodes.resize(bvh.nodes.size());
  if (!bvh.nodes.empty()) std::memcpy(records.nodes.data(), bvh.nodes.data(), bvh.nodes.size() * sizeof(Bvh4Node));
  records.leaf_triangles = bvh.leaf_triangles;
  records.stack_entries = bvh.stack_entries;
  records.depth = bvh.depth;
  return records;
}

Bvh4 to_bvh4(const formats::SceneBvh& records) {
  Bvh4 bvh;
  bvh.nodes.resize(records.nodes.size());
  if (!records.nodes.empty()) std::memcpy(bvh.nodes.data(), records.nodes.data(), records.nodes.size() * sizeof(Bvh4Node));
  bvh.leaf_triangles = records.leaf_triangles;
  bvh.stack_entries = records.stack_entries;
  bvh.depth = records.depth;
  return bvh;
}

}  // namespace exitance
