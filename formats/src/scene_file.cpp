#include "exitance/formats/scene_file.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "binary_io.h"
#include "exitance/formats/huge_pages.h"
#include "exitance/formats/probes_file.h"
#include "framed_file.h"

namespace exitance::formats {
namespace {

constexpr framing::FileKind kSceneKind{kSceneMagic, kSceneFormatVersion, kSceneHeaderSize, kOldestSceneFormatVersion};

// Bytes per triangle of the seven per-triangle arrays: positions, normals, lightmap UVs, TEXCOORD_0
// (3 corners each), material, instance and world texel size.
constexpr uint64_t kTriangleBytes = 36 + 36 + 24 + 24 + 4 + 4 + 4;
constexpr uint64_t kPageRecordSize = 12;
constexpr uint64_t kProbeRecordBytes = 16;
// Smallest size of the variable-length records (an empty name): bounds their counts by the file size.
constexpr uint64_t kMinMaterialBytes = 4 + 12 + 4 + 12 + 4 + 4 + 4;
// Version 2 appends to each material: two bindings' tex_coord, offset, rotation, scale; alpha mode,
// cutoff and base alpha.
constexpr uint64_t kMaterialVersion2Bytes = 2 * (4 + 8 + 4 + 8) + 4 + 4 + 4;
constexpr uint64_t kTextureHeaderBytes = 5 * 4;   // width, height, wrap_s, wrap_t, has_alpha
constexpr uint64_t kVertexColorBytes = 4 * 4;     // per corner: f32[3] colour, f32 alpha
// Version 3 appends to each material: the normal texture's index and binding, and its scale.
constexpr uint64_t kMaterialVersion3Bytes = 4 + (4 + 8 + 4 + 8) + 4;
constexpr uint64_t kTangentBytes = 4 * 4;  // per corner: f32[3] tangent, f32 sign
constexpr uint64_t kMinInstanceBytes = 4 + 4 + 4 + 4 + 4 + 128 + 4 + 16 + 16;
constexpr uint64_t kMinNodeBytes = 4 + 4 * 5 + 24 + 32 + 24 + 128;
constexpr uint64_t kMinCameraBytes = 4 + 4 + 4 + 6 * 4;
constexpr uint64_t kMinLightBytes = 4 + 4 + 4 + 12 + 12 + 12 + 4 + 4;

constexpr uint32_t kNodeInScene = 1u << 0;
constexpr uint32_t kNodeHasMatrix = 1u << 1;
constexpr uint32_t kHighestProbeState = uint32_t(ProbeState::Skipped);

// ---------------------------------------------------------------------------------------------
// Validation. Every check names the file, the element and the problem on one line.

std::string at(const std::string& name, const char* element, size_t index) {
  return name + ": " + element + " " + std::to_string(index) + ": ";
}

bool finite(float v) { return std::isfinite(v); }
template <typename T, size_t N>
bool finite(const std::array<T, N>& values) {
  for (T v : values)
    if (!std::isfinite(v)) return false;
  return true;
}
template <size_t N>
bool non_negative(const std::array<float, N>& values) {
  for (float v : values)
    if (!(v >= 0)) return false;
  return true;
}
bool index_in(int32_t index, size_t count) { return index >= 0 && size_t(index) < count; }

void validate_globals(const SceneFile& s, const std::string& name) {
  if (!finite(s.sky) || !non_negative(s.sky))
    throw FormatError(name + ": header: sky radiance must be finite and >= 0");
  if (!(finite(s.texel_density) && s.texel_density >= 0))
    throw FormatError(name + ": header: texel density " + std::to_string(s.texel_density) +
                      " is not a finite non-negative number");
}

void validate_triangles(const SceneFile& s, const std::string& name) {
  const SceneTriangles& t = s.triangles;
  const size_t count = t.material.size();
  if (count > kMaxSceneTriangles)
    throw FormatError(name + ": " + std::to_string(count) + " triangles exceed the limit of " +
                      std::to_string(kMaxSceneTriangles));
  if (t.instance.size() != count || t.positions.size() != 3 * count || t.normals.size() != 3 * count ||
      t.lightmap_uv.size() != 3 * count || t.uv0.size() != 3 * count)
    throw FormatError(name + ": triangle arrays disagree in length (" + std::to_string(count) +
                      " triangles need 3 corners each and one material and instance each)");
  for (size_t i = 0; i < count; ++i) {
    for (int k = 0; k < 3; ++k) {
      const size_t c = 3 * i + size_t(k);
      if (!finite(t.positions[c])) throw FormatError(at(name, "triangle", i) + "position is not finite");
      if (!finite(t.normals[c])) throw FormatError(at(name, "triangle", i) + "normal is not finite");
      if (!finite(t.lightmap_uv[c])) throw FormatError(at(name, "triangle", i) + "lightmap UV is not finite");
      if (!finite(t.uv0[c])) throw FormatError(at(name, "triangle", i) + "TEXCOORD_0 is not finite");
    }
    if (t.material[i] >= s.materials.size())
      throw FormatError(at(name, "triangle", i) + "material " + std::to_string(t.material[i]) + " does not exist (" +
                        std::to_string(s.materials.size()) + " materials)");
    const uint32_t instance = t.instance[i];
    if (instance >= s.instances.size())
      throw FormatError(at(name, "triangle", i) + "instance " + std::to_string(instance) + " does not exist (" +
                        std::to_string(s.instances.size()) + " instances)");
    const InstanceRecord& r = s.instances[instance];
    if (i < r.first_triangle || i - r.first_triangle >= r.triangle_count)
      throw FormatError(at(name, "triangle", i) + "lies outside the triangle range of its instance " +
                        std::to_string(instance));
  }
}

void validate_binding(const TextureBindingRecord& b, size_t textures, const std::string& where) {
  if (b.texture != -1 && !index_in(b.texture, textures))
    throw FormatError(where + "texture " + std::to_string(b.texture) + " does not exist (" + std::to_string(textures) +
                      " textures)");
  if (b.tex_coord > 1) throw FormatError(where + "tex_coord " + std::to_string(b.tex_coord) + " is not 0 or 1");
  if (!finite(b.offset) || !finite(b.rotation) || !finite(b.scale))
    throw FormatError(where + "texture transform is not finite");
}

void validate_materials(const SceneFile& s, const std::string& name) {
  for (size_t i = 0; i < s.materials.size(); ++i) {
    const MaterialRecord& m = s.materials[i];
    if (m.name.size() > kMaxSceneNameBytes) throw FormatError(at(name, "material", i) + "name is too long");
    if (!finite(m.base_color) || !non_negative(m.base_color))
      throw FormatError(at(name, "material", i) + "base colour must be finite and >= 0");
    if (!(m.metallic >= 0 && m.metallic <= 1))
      throw FormatError(at(name, "material", i) + "metallic must be in [0, 1]");
    if (!finite(m.emission) || !non_negative(m.emission))
      throw FormatError(at(name, "material", i) + "emission must be finite and >= 0");
    validate_binding(m.base_color_texture, s.textures.size(), at(name, "material", i) + "base colour texture: ");
    validate_binding(m.emissive_texture, s.textures.size(), at(name, "material", i) + "emissive texture: ");
    validate_binding(m.normal_texture, s.textures.size(), at(name, "material", i) + "normal texture: ");
    if (!finite(m.normal_scale)) throw FormatError(at(name, "material", i) + "normal scale is not finite");
    if (uint32_t(m.alpha_mode) > uint32_t(AlphaMode::Blend))
      throw FormatError(at(name, "material", i) + "alpha mode " + std::to_string(uint32_t(m.alpha_mode)) +
                        " is not OPAQUE (0), MASK (1) or BLEND (2)");
    if (!(finite(m.alpha_cutoff) && m.alpha_cutoff >= 0))
      throw FormatError(at(name, "material", i) + "alpha cutoff must be finite and >= 0");
    if (!(m.base_alpha >= 0 && m.base_alpha <= 1))
      throw FormatError(at(name, "material", i) + "base alpha must be in [0, 1]");
  }
}

void validate_texture(const TextureRecord& t, const std::string& where) {
  if (t.width == 0 || t.height == 0 || t.width > kMaxSceneTextureSize || t.height > kMaxSceneTextureSize)
    throw FormatError(where + "size " + std::to_string(t.width) + " x " + std::to_string(t.height) +
                      " is not within 1 .. " + std::to_string(kMaxSceneTextureSize));
  if (uint32_t(t.wrap_s) > uint32_t(TextureWrap::MirroredRepeat) ||
      uint32_t(t.wrap_t) > uint32_t(TextureWrap::MirroredRepeat))
    throw FormatError(where + "wrap modes " + std::to_string(uint32_t(t.wrap_s)) + ", " +
                      std::to_string(uint32_t(t.wrap_t)) + " are not repeat (0), clamp (1) or mirrored repeat (2)");
  const uint64_t texels = uint64_t(t.width) * t.height;
  if (t.rgb.size() != 3 * texels || (!t.alpha.empty() && t.alpha.size() != texels))
    throw FormatError(where + "pixel arrays do not hold " + std::to_string(texels) + " texels");
  for (size_t k = 0; k < t.rgb.size(); ++k)
    if (!finite(t.rgb[k])) throw FormatError(where + "texel " + std::to_string(k / 3) + ": colour is not finite");
  for (size_t k = 0; k < t.alpha.size(); ++k)
    if (!(t.alpha[k] >= 0 && t.alpha[k] <= 1))
      throw FormatError(where + "texel " + std::to_string(k) + ": alpha is not in [0, 1]");
}

void validate_textures(const SceneFile& s, const std::string& name) {
  for (size_t i = 0; i < s.textures.size(); ++i) validate_texture(s.textures[i], at(name, "texture", i));
  const TextureRecord& sky = s.sky_environment;
  if (sky.width != 0 || sky.height != 0 || !sky.rgb.empty() || !sky.alpha.empty())
    validate_texture(sky, name + ": sky environment: ");
}

void validate_vertex_colors(const SceneFile& s, const std::string& name) {
  if (s.vertex_color.empty() && s.vertex_alpha.empty()) return;
  const size_t corners = 3 * s.triangles.count();
  if (s.vertex_color.size() != corners || s.vertex_alpha.size() != corners)
    throw FormatError(name + ": vertex colours: " + std::to_string(s.vertex_color.size()) + " colours and " +
                      std::to_string(s.vertex_alpha.size()) + " alphas for " + std::to_string(corners) + " corners");
  for (size_t c = 0; c < corners; ++c)
    if (!finite(s.vertex_color[c]) || !finite(s.vertex_alpha[c]))
      throw FormatError(at(name, "triangle", c / 3) + "vertex colour is not finite");
}

void validate_tangents(const SceneFile& s, const std::string& name) {
  if (s.tangents.empty() && s.tangent_signs.empty()) return;
  const size_t corners = 3 * s.triangles.count();
  if (s.tangents.size() != corners || s.tangent_signs.size() != corners)
    throw FormatError(name + ": tangents: " + std::to_string(s.tangents.size()) + " tangents and " +
                      std::to_string(s.tangent_signs.size()) + " signs for " + std::to_string(corners) + " corners");
  for (size_t c = 0; c < corners; ++c) {
    if (!finite(s.tangents[c])) throw FormatError(at(name, "triangle", c / 3) + "tangent is not finite");
    if (s.tangent_signs[c] != 1.0f && s.tangent_signs[c] != -1.0f)
      throw FormatError(at(name, "triangle", c / 3) + "tangent sign is not +1 or -1");
  }
}

// What versions 1-3 cannot hold: a triangle in several leaf slots (spatial splits, version 4).
void refuse_version4_content(const SceneFile& s, const std::string& name, uint32_t version) {
  if (s.bvh.leaf_triangles.size() != s.triangles.count())
    throw FormatError(name + ": bvh: " + std::to_string(s.bvh.leaf_triangles.size()) + " leaf slots for " +
                      std::to_string(s.triangles.count()) + " triangles: a triangle in several leaf slots is not stored by scene.bin version " +
                      std::to_string(version));
}

// What version 2 cannot hold, for encode_scene(scene, 2).
void refuse_version3_content(const SceneFile& s, const std::string& name, uint32_t version) {
  const std::string why = " is not stored by scene.bin version " + std::to_string(version);
  if (!s.tangents.empty()) throw FormatError(name + ": tangents:" + why);
  const MaterialRecord defaults;
  for (size_t i = 0; i < s.materials.size(); ++i)
    if (s.materials[i].normal_texture.texture != -1 || s.materials[i].normal_scale != defaults.normal_scale)
      throw FormatError(at(name, "material", i) + "normal textures are" + why.substr(3));
}

// What version 1 cannot hold, for encode_scene(scene, 1).
void refuse_version2_content(const SceneFile& s, const std::string& name) {
  const std::string why = " is not stored by scene.bin version 1";
  if (!s.textures.empty()) throw FormatError(name + ": textures:" + why);
  if (s.sky_environment.width != 0) throw FormatError(name + ": sky environment:" + why);
  if (!s.vertex_color.empty()) throw FormatError(name + ": vertex colours:" + why);
  const MaterialRecord defaults;
  for (size_t i = 0; i < s.materials.size(); ++i) {
    const MaterialRecord& m = s.materials[i];
    if (m.alpha_mode != AlphaMode::Opaque || m.alpha_cutoff != defaults.alpha_cutoff ||
        m.base_alpha != defaults.base_alpha || m.base_color_texture.texture != -1 || m.emissive_texture.texture != -1)
      throw FormatError(at(name, "material", i) + "textures and alpha modes are" + why.substr(3));
  }
}

void validate_pages(const SceneFile& s, const std::string& name) {
  uint64_t atlas_texels = 0, live = 0;
  for (size_t p = 0; p < s.texels.pages.size(); ++p) {
    const TexelPageRecord& page = s.texels.pages[p];
    if (page.width == 0 || page.height == 0 || page.width > kMaxScenePageSize || page.height > kMaxScenePageSize)
      throw FormatError(at(name, "page", p) + "size " + std::to_string(page.width) + " x " +
                        std::to_string(page.height) + " is not within 1 .. " + std::to_string(kMaxScenePageSize));
    const uint64_t area = uint64_t(page.width) * page.height;
    atlas_texels += area;
    if (atlas_texels > kMaxSceneAtlasTexels)
      throw FormatError(at(name, "page", p) + "the atlas exceeds the limit of " + std::to_string(kMaxSceneAtlasTexels) +
                        " texels");
    if (page.live_texels > area)
      throw FormatError(at(name, "page", p) + std::to_string(page.live_texels) + " live texels on " +
                        std::to_string(area) + " texels");
    live += page.live_texels;
  }
  if (live != s.texels.texels.size())
    throw FormatError(name + ": pages list " + std::to_string(live) + " live texels, there are " +
                      std::to_string(s.texels.texels.size()));
}

void validate_instances(const SceneFile& s, const std::string& name) {
  const size_t triangles = s.triangles.count();
  for (size_t i = 0; i < s.instances.size(); ++i) {
    const InstanceRecord& r = s.instances[i];
    if (r.name.size() > kMaxSceneNameBytes) throw FormatError(at(name, "instance", i) + "name is too long");
    if (r.node != -1) {
      if (!index_in(r.node, s.nodes.size()))
        throw FormatError(at(name, "instance", i) + "node " + std::to_string(r.node) + " does not exist");
      const NodeRecord& node = s.nodes[size_t(r.node)];
      if (node.mesh != r.mesh)
        throw FormatError(at(name, "instance", i) + "mesh " + std::to_string(r.mesh) + " is not node " +
                          std::to_string(r.node) + "'s mesh " + std::to_string(node.mesh));
      if (!node.in_scene)
        throw FormatError(at(name, "instance", i) + "node " + std::to_string(r.node) + " is not in the scene");
    }
    if (r.mesh < -1) throw FormatError(at(name, "instance", i) + "mesh " + std::to_string(r.mesh) + " is not an index");
    if (uint64_t(r.first_triangle) + r.triangle_count > triangles)
      throw FormatError(at(name, "instance", i) + "triangles " + std::to_string(r.first_triangle) + " + " +
                        std::to_string(r.triangle_count) + " run past the " + std::to_string(triangles) + " triangles");
    for (uint32_t t = r.first_triangle; t < r.first_triangle + r.triangle_count; ++t)
      if (s.triangles.instance[t] != i)
        throw FormatError(at(name, "instance", i) + "triangle " + std::to_string(t) +
                          " in its range belongs to instance " + std::to_string(s.triangles.instance[t]));
    if (!finite(r.world)) throw FormatError(at(name, "instance", i) + "world transform is not finite");
    if (r.page >= s.texels.pages.size())
      throw FormatError(at(name, "instance", i) + "page " + std::to_string(r.page) + " does not exist (" +
                        std::to_string(s.texels.pages.size()) + " pages)");
    const TexelPageRecord& page = s.texels.pages[r.page];
    if (uint64_t(r.x) + r.width > page.width || uint64_t(r.y) + r.height > page.height)
      throw FormatError(at(name, "instance", i) + "rectangle " + std::to_string(r.x) + ", " + std::to_string(r.y) +
                        ", " + std::to_string(r.width) + " x " + std::to_string(r.height) + " does not fit page " +
                        std::to_string(r.page));
    if (!finite(r.scale_offset)) throw FormatError(at(name, "instance", i) + "scale_offset is not finite");
  }
}

void validate_nodes(const SceneFile& s, const std::string& name) {
  const size_t count = s.nodes.size();
  for (size_t i = 0; i < count; ++i) {
    const NodeRecord& n = s.nodes[i];
    if (n.name.size() > kMaxSceneNameBytes) throw FormatError(at(name, "node", i) + "name is too long");
    if (n.parent != -1) {
      if (!index_in(n.parent, count) || size_t(n.parent) == i)
        throw FormatError(at(name, "node", i) + "parent " + std::to_string(n.parent) + " is not another node");
      if (s.nodes[size_t(n.parent)].in_scene != n.in_scene)
        throw FormatError(at(name, "node", i) + "is " + (n.in_scene ? "" : "not ") + "in the scene but its parent " +
                          std::to_string(n.parent) + (n.in_scene ? " is not" : " is"));
    }
    if (n.mesh < -1) throw FormatError(at(name, "node", i) + "mesh " + std::to_string(n.mesh) + " is not an index");
    if (n.light != -1 && (!index_in(n.light, s.lights.size()) || s.lights[size_t(n.light)].node != int32_t(i)))
      throw FormatError(at(name, "node", i) + "light " + std::to_string(n.light) +
                        " does not exist or is not placed by it");
    if (n.camera != -1 && (!index_in(n.camera, s.cameras.size()) || s.cameras[size_t(n.camera)].node != int32_t(i)))
      throw FormatError(at(name, "node", i) + "camera " + std::to_string(n.camera) +
                        " does not exist or is not placed by it");
    if (!finite(n.translation) || !finite(n.rotation) || !finite(n.scale) || !finite(n.matrix))
      throw FormatError(at(name, "node", i) + "local transform is not finite");
    if (n.has_matrix) {
      if (n.translation != std::array<double, 3>{0, 0, 0} || n.rotation != std::array<double, 4>{0, 0, 0, 1} ||
          n.scale != std::array<double, 3>{1, 1, 1})
        throw FormatError(at(name, "node", i) + "has a matrix and a translation, rotation or scale");
    } else {
      if (n.matrix != kIdentityMatrix)
        throw FormatError(at(name, "node", i) + "has a matrix but its matrix flag is clear");
      const double q = n.rotation[0] * n.rotation[0] + n.rotation[1] * n.rotation[1] + n.rotation[2] * n.rotation[2] +
                       n.rotation[3] * n.rotation[3];
      if (!(q > 1e-24)) throw FormatError(at(name, "node", i) + "rotation quaternion has zero length");
    }
  }
  // Parent links form a forest at most kMaxSceneNodeDepth deep: walk each chain up to a node of
  // known depth, then label the chain. A chain longer than the limit is cyclic or too deep.
  std::vector<uint32_t> depth(count, 0);  // 0 = not yet known, else depth + 1
  std::vector<uint32_t> chain;
  for (size_t i = 0; i < count; ++i) {
    chain.clear();
    size_t n = i;
    uint32_t base = 0;
    for (;;) {
      if (depth[n] != 0) {
        base = depth[n];
        break;
      }
      chain.push_back(uint32_t(n));
      if (chain.size() > kMaxSceneNodeDepth + 1)
        throw FormatError(at(name, "node", i) + "hierarchy is cyclic or deeper than " +
                          std::to_string(kMaxSceneNodeDepth) + " levels");
      if (s.nodes[n].parent == -1) break;
      n = size_t(s.nodes[n].parent);
    }
    if (base + chain.size() > kMaxSceneNodeDepth + 1)
      throw FormatError(at(name, "node", i) + "hierarchy is deeper than " + std::to_string(kMaxSceneNodeDepth) +
                        " levels");
    for (size_t k = chain.size(); k-- > 0;) depth[chain[k]] = base + uint32_t(chain.size() - k);
  }
}

void validate_cameras(const SceneFile& s, const std::string& name) {
  for (size_t i = 0; i < s.cameras.size(); ++i) {
    const CameraRecord& c = s.cameras[i];
    const std::string where = at(name, "camera", i);
    if (c.name.size() > kMaxSceneNameBytes) throw FormatError(where + "name is too long");
    if (c.node != -1 && (!index_in(c.node, s.nodes.size()) || s.nodes[size_t(c.node)].camera != int32_t(i)))
      throw FormatError(where + "node " + std::to_string(c.node) + " does not exist or does not place it");
    if (!(finite(c.yfov) && finite(c.aspect_ratio) && finite(c.xmag) && finite(c.ymag) && finite(c.znear) &&
          finite(c.zfar)))
      throw FormatError(where + "projection is not finite");
    if (c.type == CameraType::Perspective) {
      if (!(c.yfov > 0 && c.aspect_ratio >= 0 && c.znear > 0 && (c.zfar == 0 || c.zfar > c.znear)))
        throw FormatError(where + "perspective needs yfov > 0, aspect_ratio >= 0, znear > 0, zfar 0 or > znear");
      if (c.xmag != 0 || c.ymag != 0) throw FormatError(where + "perspective camera with xmag/ymag");
    } else if (c.type == CameraType::Orthographic) {
      if (!(c.xmag != 0 && c.ymag != 0 && c.znear >= 0 && c.zfar > c.znear))
        throw FormatError(where + "orthographic needs non-zero xmag and ymag, znear >= 0, zfar > znear");
      if (c.yfov != 0 || c.aspect_ratio != 0) throw FormatError(where + "orthographic camera with yfov/aspect_ratio");
    } else {
      throw FormatError(where + "type " + std::to_string(uint32_t(c.type)) +
                        " is not perspective (0) or orthographic (1)");
    }
  }
}

void validate_lights(const SceneFile& s, const std::string& name) {
  for (size_t i = 0; i < s.lights.size(); ++i) {
    const LightRecord& l = s.lights[i];
    const std::string where = at(name, "light", i);
    if (l.name.size() > kMaxSceneNameBytes) throw FormatError(where + "name is too long");
    if (l.node != -1 && (!index_in(l.node, s.nodes.size()) || s.nodes[size_t(l.node)].light != int32_t(i)))
      throw FormatError(where + "node " + std::to_string(l.node) + " does not exist or does not place it");
    if (uint32_t(l.type) > uint32_t(LightType::Directional))
      throw FormatError(where + "type " + std::to_string(uint32_t(l.type)) +
                        " is not point (0), spot (1) or directional (2)");
    if (!finite(l.position)) throw FormatError(where + "position is not finite");
    const double len = std::sqrt(double(l.direction[0]) * l.direction[0] + double(l.direction[1]) * l.direction[1] +
                                 double(l.direction[2]) * l.direction[2]);
    if (!finite(l.direction) || !(std::fabs(len - 1.0) <= 1e-3))
      throw FormatError(where + "direction is not a unit vector");
    if (!finite(l.intensity) || !non_negative(l.intensity))
      throw FormatError(where + "intensity must be finite and >= 0");
    if (!(l.cos_inner >= -1 && l.cos_inner <= 1 && l.cos_outer >= -1 && l.cos_outer <= 1))
      throw FormatError(where + "cone cosines must be in [-1, 1]");
    if (l.type == LightType::Spot && !(l.cos_outer <= l.cos_inner))
      throw FormatError(where + "spot cos_outer " + std::to_string(l.cos_outer) + " exceeds cos_inner " +
                        std::to_string(l.cos_inner));
  }
}

void validate_texels(const SceneFile& s, const std::string& name) {
  const TexelGBufferRecords& g = s.texels;
  const size_t triangles = s.triangles.count();
  size_t index = 0;
  for (size_t p = 0; p < g.pages.size(); ++p) {
    const TexelPageRecord& page = g.pages[p];
    uint64_t previous_code = 0;
    for (uint32_t k = 0; k < page.live_texels; ++k, ++index) {
      const TexelRecord& t = g.texels[index];
      // Built only for an error: a string per texel would cost more than the checks at 10 M texels.
      const auto where = [&] { return at(name, "texel", index); };
      if (t.triangle >= triangles)
        throw FormatError(where() + "triangle " + std::to_string(t.triangle) + " does not exist (" +
                          std::to_string(triangles) + " triangles)");
      if (t.x >= page.width || t.y >= page.height)
        throw FormatError(where() + "(" + std::to_string(t.x) + ", " + std::to_string(t.y) + ") lies outside page " +
                          std::to_string(p) + " (" + std::to_string(page.width) + " x " + std::to_string(page.height) +
                          ")");
      const uint64_t code = uint64_t(texel_morton_code(t.x, t.y)) + 1;
      if (code <= previous_code)
        throw FormatError(where() + "(" + std::to_string(t.x) + ", " + std::to_string(t.y) +
                          ") is not after the previous texel of page " + std::to_string(p) + " in Morton order");
      previous_code = code;
      const uint32_t instance = s.triangles.instance[t.triangle];
      if (s.instances[instance].page != p)
        throw FormatError(where() + "its triangle " + std::to_string(t.triangle) + " belongs to instance " +
                          std::to_string(instance) + " on page " + std::to_string(s.instances[instance].page) +
                          ", not page " + std::to_string(p));
      if (!(t.b1 >= 0 && t.b1 <= 1 && t.b2 >= 0 && t.b2 <= 1 && t.b1 + t.b2 <= 1.000001f))
        throw FormatError(where() + "barycentrics " + std::to_string(t.b1) + ", " + std::to_string(t.b2) +
                          " are not on the triangle");
    }
  }
  if (g.triangle_texel_size.size() != triangles)
    throw FormatError(name + ": " + std::to_string(g.triangle_texel_size.size()) + " world texel sizes for " +
                      std::to_string(triangles) + " triangles");
  for (size_t t = 0; t < triangles; ++t)
    if (!(finite(g.triangle_texel_size[t]) && g.triangle_texel_size[t] >= 0))
      throw FormatError(at(name, "triangle", t) + "world texel size " + std::to_string(g.triangle_texel_size[t]) +
                        " is not a finite non-negative number");
  for (size_t i = 0; i < g.partial_coverage.size(); ++i) {
    const PartialCoverageRecord& c = g.partial_coverage[i];
    if (c.texel >= g.texels.size() || (i > 0 && c.texel <= g.partial_coverage[i - 1].texel))
      throw FormatError(at(name, "partial coverage", i) + "texel " + std::to_string(c.texel) +
                        " is out of range or not after the previous one");
    if (!(c.coverage > 0 && c.coverage < 1))
      throw FormatError(at(name, "partial coverage", i) + "coverage " + std::to_string(c.coverage) +
                        " is not in (0, 1)");
  }
  for (size_t i = 0; i < g.moved.size(); ++i) {
    const MovedTexelRecord& m = g.moved[i];
    if (m.texel >= g.texels.size() || (i > 0 && m.texel <= g.moved[i - 1].texel))
      throw FormatError(at(name, "moved texel", i) + "texel " + std::to_string(m.texel) +
                        " is out of range or not after the previous moved texel");
    if (!finite(m.position)) throw FormatError(at(name, "moved texel", i) + "position is not finite");
  }
}

void validate_probe_layout(const ProbeGrid& grid, const std::string& name) {
  const bool none = grid.counts == std::array<uint32_t, 3>{0, 0, 0};
  if (none) {
    if (!grid.probes.empty() || grid.origin != Float3{0, 0, 0} || grid.spacing != Float3{0, 0, 0})
      throw FormatError(name + ": header: no probe grid (counts 0) but origin, spacing or probes are set");
    return;
  }
  if (!finite(grid.origin)) throw FormatError(name + ": header: probe origin is not finite");
  for (int a = 0; a < 3; ++a) {
    if (!(finite(grid.spacing[a]) && grid.spacing[a] > 0))
      throw FormatError(name + ": header: probe spacing on axis " + std::to_string(a) +
                        " is not a positive finite number");
    if (grid.counts[a] == 0) throw FormatError(name + ": header: probe counts include a zero");
  }
  const uint64_t xy = uint64_t(grid.counts[0]) * grid.counts[1];
  if (xy > kMaxProbeCount || xy * grid.counts[2] > kMaxProbeCount)
    throw FormatError(name + ": header: probe counts exceed the limit of " + std::to_string(kMaxProbeCount) +
                      " probes");
  if (grid.probes.size() != xy * grid.counts[2])
    throw FormatError(name + ": " + std::to_string(grid.probes.size()) + " probes for a grid of " +
                      std::to_string(grid.counts[0]) + " x " + std::to_string(grid.counts[1]) + " x " +
                      std::to_string(grid.counts[2]));
  for (size_t i = 0; i < grid.probes.size(); ++i) {
    if (!finite(grid.probes[i].position)) throw FormatError(at(name, "probe", i) + "position is not finite");
    if (uint32_t(grid.probes[i].state) > kHighestProbeState)
      throw FormatError(at(name, "probe", i) + "state " + std::to_string(uint32_t(grid.probes[i].state)) +
                        " is not a known ProbeState (0..3)");
  }
}

// The BVH is a tree over every scene triangle: each non-root node has exactly one parent, with a
// lower index (depth-first flattening puts children after parents, so there is no cycle); leaf
// ranges partition the leaf slots; the slots hold each triangle exactly once; boxes are finite,
// non-empty and contain what is below them; stack_entries and depth are what the tree needs.
void validate_bvh(const SceneFile& s, const std::string& name) {
  const SceneBvh& bvh = s.bvh;
  const size_t triangles = s.triangles.count();
  const size_t node_count = bvh.nodes.size();
  if (node_count == 0) throw FormatError(name + ": bvh: no root node");
  if (node_count > kMaxSceneTriangles) throw FormatError(name + ": bvh: too many nodes");
  // Spatial splits put a large triangle's fragments in several leaves: up to two slots per triangle.
  if (bvh.leaf_triangles.size() < triangles || bvh.leaf_triangles.size() > 2 * triangles)
    throw FormatError(name + ": bvh: " + std::to_string(bvh.leaf_triangles.size()) + " leaf slots for " +
                      std::to_string(triangles) + " triangles (each triangle is in one to two slots in all)");
  std::vector<uint8_t> seen_triangle(triangles, 0);
  for (size_t i = 0; i < bvh.leaf_triangles.size(); ++i) {
    const uint32_t t = bvh.leaf_triangles[i];
    if (t >= triangles)
      throw FormatError(name + ": bvh: leaf slot " + std::to_string(i) + ": triangle " + std::to_string(t) +
                        " does not exist");
    seen_triangle[t] = 1;
  }
  for (size_t t = 0; t < triangles; ++t)
    if (!seen_triangle[t]) throw FormatError(name + ": bvh: triangle " + std::to_string(t) + " is in no leaf slot");
  // Per triangle, the union of the boxes of the leaves that hold it: it must contain the corners.
  std::vector<float> cover(triangles * 6);
  for (size_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) cover[t * 6 + size_t(k)] = INFINITY, cover[t * 6 + 3 + size_t(k)] = -INFINITY;
  }
  std::vector<uint8_t> has_parent(node_count, 0), slot_used(bvh.leaf_triangles.size(), 0);
  for (size_t i = 0; i < node_count; ++i) {
    const BvhNodeRecord& n = bvh.nodes[i];
    const auto where = [&] { return name + ": bvh node " + std::to_string(i) + ": "; };
    for (int c = 0; c < 4; ++c) {
      const uint32_t word = n.child[c];
      const float box[6] = {n.lo_x[c], n.hi_x[c], n.lo_y[c], n.hi_y[c], n.lo_z[c], n.hi_z[c]};
      for (float v : box)
        if (!finite(v)) throw FormatError(where() + "child " + std::to_string(c) + " bounds are not finite");
      if (word == kSceneBvhEmptyChild) continue;
      if (!(box[0] <= box[1] && box[2] <= box[3] && box[4] <= box[5]))
        throw FormatError(where() + "child " + std::to_string(c) + " box is inverted");
      if (word & kSceneBvhLeafBit) {
        const uint64_t first = (word & ~kSceneBvhLeafBit) >> 2, count = (word & 3u) + 1;
        if (first + count > bvh.leaf_triangles.size())
          throw FormatError(where() + "child " + std::to_string(c) + " leaf slots " + std::to_string(first) + " + " +
                            std::to_string(count) + " run past the " + std::to_string(bvh.leaf_triangles.size()) +
                            " leaf slots");
        for (uint64_t k = first; k < first + count; ++k) {
          if (slot_used[k])
            throw FormatError(where() + "child " + std::to_string(c) + " leaf slot " + std::to_string(k) +
                              " is in more than one leaf");
          slot_used[k] = 1;
          const size_t t = bvh.leaf_triangles[k];
          const float lo[3] = {n.lo_x[c], n.lo_y[c], n.lo_z[c]}, hi[3] = {n.hi_x[c], n.hi_y[c], n.hi_z[c]};
          for (int a = 0; a < 3; ++a) {
            cover[t * 6 + size_t(a)] = std::min(cover[t * 6 + size_t(a)], lo[a]);
            cover[t * 6 + 3 + size_t(a)] = std::max(cover[t * 6 + 3 + size_t(a)], hi[a]);
          }
        }
      } else {
        if (word <= i || word >= node_count)
          throw FormatError(where() + "child " + std::to_string(c) + " index " + std::to_string(word) +
                            (word >= node_count ? " is out of range (" + std::to_string(node_count) + " nodes)"
                                                : " is not after its parent (depth-first order)"));
        if (has_parent[word])
          throw FormatError(where() + "child node " + std::to_string(word) + " has more than one parent");
        has_parent[word] = 1;
        const BvhNodeRecord& child = bvh.nodes[word];
        for (int g = 0; g < 4; ++g) {
          if (child.child[g] == kSceneBvhEmptyChild) continue;
          if (!(child.lo_x[g] >= n.lo_x[c] && child.hi_x[g] <= n.hi_x[c] && child.lo_y[g] >= n.lo_y[c] &&
                child.hi_y[g] <= n.hi_y[c] && child.lo_z[g] >= n.lo_z[c] && child.hi_z[g] <= n.hi_z[c]))
            throw FormatError(where() + "child " + std::to_string(c) + " box does not contain node " +
                              std::to_string(word) + "'s child " + std::to_string(g));
        }
      }
    }
  }
  for (size_t i = 1; i < node_count; ++i)
    if (!has_parent[i]) throw FormatError(name + ": bvh node " + std::to_string(i) + ": no node lists it as a child");
  for (size_t k = 0; k < slot_used.size(); ++k)
    if (!slot_used[k]) throw FormatError(name + ": bvh: leaf slot " + std::to_string(k) + " is in no leaf");
  for (size_t t = 0; t < triangles; ++t)
    for (int v = 0; v < 3; ++v) {
      const Float3& p = s.triangles.positions[3 * t + size_t(v)];
      for (int a = 0; a < 3; ++a)
        if (!(p[a] >= cover[t * 6 + size_t(a)] && p[a] <= cover[t * 6 + 3 + size_t(a)]))
          throw FormatError(name + ": bvh: the leaf boxes of triangle " + std::to_string(t) +
                            " do not contain its corner " + std::to_string(v));
    }
  // Children have higher indices than parents: one pass from the back computes, per node, the
  // traversal stack entries its subtree needs (the builder's rule: visiting a node pushes its
  // non-empty children and pops itself) and its height in inner nodes.
  std::vector<uint32_t> stack(node_count, 0), height(node_count, 1);
  for (size_t i = node_count; i-- > 0;) {
    uint32_t below = 0, tallest = 0, children = 0;
    for (uint32_t word : bvh.nodes[i].child) {
      if (word == kSceneBvhEmptyChild) continue;
      ++children;
      if (!(word & kSceneBvhLeafBit)) below = std::max(below, stack[word]), tallest = std::max(tallest, height[word]);
    }
    stack[i] = below + children;
    height[i] = tallest + 1;
  }
  const bool empty_root = stack[0] == 0;
  const uint32_t needed_stack = empty_root ? 1 : stack[0];
  const uint32_t needed_depth = empty_root ? 0 : height[0];
  if (bvh.stack_entries != needed_stack)
    throw FormatError(name + ": bvh: stack bound " + std::to_string(bvh.stack_entries) + " is not the " +
                      std::to_string(needed_stack) + " the tree needs");
  if (bvh.depth != needed_depth)
    throw FormatError(name + ": bvh: depth " + std::to_string(bvh.depth) + " is not the tree's " +
                      std::to_string(needed_depth));
}

// ---------------------------------------------------------------------------------------------
// Payload layout helpers.

uint64_t fixed_payload_bytes(uint64_t triangles, uint64_t bvh_nodes, uint64_t leaf_slots, uint64_t pages,
                             uint64_t texels, uint64_t partial, uint64_t moved, uint64_t probes) {
  return triangles * kTriangleBytes + bvh_nodes * kSceneBvhNodeSize + leaf_slots * 4 + pages * kPageRecordSize +
         texels * kSceneTexelSize + partial * kScenePartialCoverageSize + moved * kSceneMovedTexelSize +
         probes * kProbeRecordBytes;
}

void put_name(binary_io::LittleEndianWriter& w, const std::string& text) {
  w.u32(uint32_t(text.size()));
  w.bytes(text.data(), text.size());
}
template <size_t N>
void put(binary_io::LittleEndianWriter& w, const std::array<float, N>& v) {
  for (float x : v) w.f32(x);
}
template <size_t N>
void put(binary_io::LittleEndianWriter& w, const std::array<double, N>& v) {
  for (double x : v) w.f64(x);
}

void put_texture(binary_io::LittleEndianWriter& w, const TextureRecord& t) {
  w.u32(t.width);
  w.u32(t.height);
  w.u32(uint32_t(t.wrap_s));
  w.u32(uint32_t(t.wrap_t));
  w.u32(t.alpha.empty() ? 0 : 1);
  for (float v : t.rgb) w.f32(v);
  for (float v : t.alpha) w.f32(v);
}

std::string get_name(binary_io::LittleEndianReader& r, const std::string& where) {
  const uint32_t length = r.u32();
  if (length > kMaxSceneNameBytes)
    throw FormatError(where + "name length " + std::to_string(length) + " exceeds " +
                      std::to_string(kMaxSceneNameBytes));
  if (length > r.remaining()) throw FormatError(where + "name runs past the end of the payload");
  return r.text(length);
}
// The triangle table's arrays in the file's order, for the writer and the reader alike (each moves
// an array with its words()). Each array holds 3 entries per triangle, or 1 (material, instance).
template <class Triangles, class Words>
void for_each_triangle_array(Triangles& t, Words&& words) {
  words(t.positions, 3);
  words(t.normals, 3);
  words(t.lightmap_uv, 3);
  words(t.uv0, 3);
  words(t.material, 1);
  words(t.instance, 1);
}
template <size_t N>
void get(binary_io::LittleEndianReader& r, std::array<float, N>& v) {
  for (float& x : v) x = r.f32();
}
template <size_t N>
void get(binary_io::LittleEndianReader& r, std::array<double, N>& v) {
  for (double& x : v) x = r.f64();
}
bool get_bool(binary_io::LittleEndianReader& r, const std::string& where, const char* what) {
  const uint32_t v = r.u32();
  if (v > 1) throw FormatError(where + what + " is " + std::to_string(v) + ", not 0 or 1");
  return v == 1;
}

// The size and flags are checked, and the pixel bytes against what is left of the payload, before
// anything is allocated.
TextureRecord get_texture(binary_io::LittleEndianReader& r, const std::string& where) {
  if (r.remaining() < kTextureHeaderBytes) throw FormatError(where + "record runs past the end of the payload");
  TextureRecord t;
  t.width = r.u32();
  t.height = r.u32();
  t.wrap_s = TextureWrap(r.u32());
  t.wrap_t = TextureWrap(r.u32());
  const bool has_alpha = get_bool(r, where, "has_alpha");
  if (t.width == 0 || t.height == 0 || t.width > kMaxSceneTextureSize || t.height > kMaxSceneTextureSize)
    throw FormatError(where + "size " + std::to_string(t.width) + " x " + std::to_string(t.height) +
                      " is not within 1 .. " + std::to_string(kMaxSceneTextureSize));
  const uint64_t texels = uint64_t(t.width) * t.height;
  const uint64_t bytes = texels * (has_alpha ? 16 : 12);
  if (bytes > r.remaining())
    throw FormatError(where + std::to_string(t.width) + " x " + std::to_string(t.height) + " texels need " +
                      std::to_string(bytes) + " bytes, the payload has " + std::to_string(r.remaining()) + " left");
  t.rgb.resize(size_t(texels) * 3);
  for (float& v : t.rgb) v = r.f32();
  if (has_alpha) {
    t.alpha.resize(size_t(texels));
    for (float& v : t.alpha) v = r.f32();
  }
  return t;
}

}  // namespace

void validate_scene_file(const SceneFile& s, const std::string& name) {
  validate_globals(s, name);
  validate_textures(s, name);
  validate_materials(s, name);
  validate_vertex_colors(s, name);
  validate_tangents(s, name);
  validate_pages(s, name);
  validate_nodes(s, name);
  validate_triangles(s, name);
  validate_instances(s, name);
  validate_cameras(s, name);
  validate_lights(s, name);
  validate_texels(s, name);
  validate_probe_layout(s.probes, name);
  validate_bvh(s, name);
}

// encode_scene writes these arrays with binary_io's words(): their bytes are their 4-byte fields in order.
static_assert(sizeof(Float2) == 8 && sizeof(Float3) == 12);
static_assert(sizeof(PartialCoverageRecord) == 8 && offsetof(PartialCoverageRecord, coverage) == 4);

std::vector<uint8_t> encode_scene(const SceneFile& s, uint32_t version) {
  const std::string writing = "scene.bin (writing)";
  if (version < kOldestSceneFormatVersion || version > kSceneFormatVersion)
    throw FormatError(writing + ": format version " + std::to_string(version) + " is not one this writer writes");
  validate_scene_file(s, writing);
  if (version <= 3) refuse_version4_content(s, writing, version);
  if (version <= 2) refuse_version3_content(s, writing, version);
  if (version == 1) refuse_version2_content(s, writing);
  const bool has_environment = s.sky_environment.width != 0;
  const bool has_vertex_colors = !s.vertex_color.empty();
  const bool has_tangents = !s.tangents.empty();
  const SceneTriangles& t = s.triangles;
  std::vector<uint8_t> header;
  binary_io::LittleEndianWriter h(header);
  h.u32(uint32_t(t.count()));
  h.u32(uint32_t(s.materials.size()));
  h.u32(uint32_t(s.instances.size()));
  h.u32(uint32_t(s.nodes.size()));
  h.u32(uint32_t(s.cameras.size()));
  h.u32(uint32_t(s.lights.size()));
  h.u32(uint32_t(s.texels.pages.size()));
  h.u32(uint32_t(s.texels.texels.size()));
  h.u32(uint32_t(s.texels.partial_coverage.size()));
  h.u32(uint32_t(s.texels.moved.size()));
  h.u32(uint32_t(s.probes.probes.size()));
  h.u32(uint32_t(s.bvh.nodes.size()));
  h.u32(uint32_t(s.bvh.leaf_triangles.size()));
  h.u32(s.bvh.stack_entries);
  h.u32(s.bvh.depth);
  put(h, s.sky);
  h.u32(has_environment ? 1 : 0);  // sky_environment (always 0 in version 1)
  h.f32(s.texel_density);
  put(h, s.probes.origin);
  put(h, s.probes.spacing);
  for (uint32_t c : s.probes.counts) h.u32(c);
  h.u32(uint32_t(s.textures.size()));    // texture_count (version 2; reserved 0 in version 1)
  h.u32(has_vertex_colors ? 1 : 0);       // vertex_colors (version 2; reserved 0 in version 1)
  h.u32(has_tangents ? 1 : 0);            // tangents (version 3; reserved 0 before)

  const uint64_t fixed = fixed_payload_bytes(
      t.count(), s.bvh.nodes.size(), s.bvh.leaf_triangles.size(), s.texels.pages.size(), s.texels.texels.size(),
      s.texels.partial_coverage.size(), s.texels.moved.size(), s.probes.probes.size());
  // The payload is written straight after the header's placeholder, the large arrays in one copy
  // each (binary_io's words(): the same bytes as field-by-field writes).
  const framing::FileKind kind{kSceneMagic, version, kSceneHeaderSize, version};
  std::vector<uint8_t> file = framing::begin_frame(
      kind, size_t(fixed) + s.nodes.size() * kMinNodeBytes + s.instances.size() * kMinInstanceBytes);
  binary_io::LittleEndianWriter p(file);
  for_each_triangle_array(t, [&](const auto& values, size_t) { p.words(values.data(), values.size()); });
  p.words(s.texels.triangle_texel_size.data(), s.texels.triangle_texel_size.size());
  // A node's fields in the file's order are its members' order (lo_x .. hi_z, then child).
  p.words(s.bvh.nodes.data(), s.bvh.nodes.size());
  p.words(s.bvh.leaf_triangles.data(), s.bvh.leaf_triangles.size());
  for (const TexelPageRecord& page : s.texels.pages) {
    p.u32(page.width);
    p.u32(page.height);
    p.u32(page.live_texels);
  }
  const std::vector<TexelRecord>& texels = s.texels.texels;
  {
    std::vector<uint32_t> column(texels.size());
    for (size_t i = 0; i < texels.size(); ++i) column[i] = texels[i].triangle;
    p.words(column.data(), column.size());
    for (size_t i = 0; i < texels.size(); ++i) column[i] = uint32_t(texels[i].x) | (uint32_t(texels[i].y) << 16);
    p.words(column.data(), column.size());
    std::vector<Float2> barycentrics(texels.size());
    for (size_t i = 0; i < texels.size(); ++i) barycentrics[i] = {texels[i].b1, texels[i].b2};
    p.words(barycentrics.data(), barycentrics.size());
  }
  p.words(s.texels.partial_coverage.data(), s.texels.partial_coverage.size());  // texel, coverage
  for (const MovedTexelRecord& m : s.texels.moved) {
    p.u32(m.texel);
    put(p, m.position);
  }
  for (const ProbeRecord& probe : s.probes.probes) {
    put(p, probe.position);
    p.u32(uint32_t(probe.state));
  }
  for (const MaterialRecord& m : s.materials) {
    put_name(p, m.name);
    put(p, m.base_color);
    p.f32(m.metallic);
    put(p, m.emission);
    p.u32(m.double_sided ? 1 : 0);
    p.u32(uint32_t(m.base_color_texture.texture));
    p.u32(uint32_t(m.emissive_texture.texture));
    if (version >= 2) {
      for (const TextureBindingRecord* b : {&m.base_color_texture, &m.emissive_texture}) {
        p.u32(b->tex_coord);
        put(p, b->offset);
        p.f32(b->rotation);
        put(p, b->scale);
      }
      p.u32(uint32_t(m.alpha_mode));
      p.f32(m.alpha_cutoff);
      p.f32(m.base_alpha);
    }
    if (version >= 3) {
      const TextureBindingRecord& b = m.normal_texture;
      p.u32(uint32_t(b.texture));
      p.u32(b.tex_coord);
      put(p, b.offset);
      p.f32(b.rotation);
      put(p, b.scale);
      p.f32(m.normal_scale);
    }
  }
  for (const InstanceRecord& r : s.instances) {
    put_name(p, r.name);
    p.u32(uint32_t(r.node));
    p.u32(uint32_t(r.mesh));
    p.u32(r.first_triangle);
    p.u32(r.triangle_count);
    put(p, r.world);
    p.u32(r.page);
    p.u32(r.x), p.u32(r.y), p.u32(r.width), p.u32(r.height);
    put(p, r.scale_offset);
  }
  for (const NodeRecord& n : s.nodes) {
    put_name(p, n.name);
    p.u32(uint32_t(n.parent));
    p.u32(uint32_t(n.mesh));
    p.u32(uint32_t(n.light));
    p.u32(uint32_t(n.camera));
    p.u32((n.in_scene ? kNodeInScene : 0) | (n.has_matrix ? kNodeHasMatrix : 0));
    put(p, n.translation);
    put(p, n.rotation);
    put(p, n.scale);
    put(p, n.matrix);
  }
  for (const CameraRecord& c : s.cameras) {
    put_name(p, c.name);
    p.u32(uint32_t(c.node));
    p.u32(uint32_t(c.type));
    for (float v : {c.yfov, c.aspect_ratio, c.xmag, c.ymag, c.znear, c.zfar}) p.f32(v);
  }
  for (const LightRecord& l : s.lights) {
    put_name(p, l.name);
    p.u32(uint32_t(l.node));
    p.u32(uint32_t(l.type));
    put(p, l.position);
    put(p, l.direction);
    put(p, l.intensity);
    p.f32(l.cos_inner);
    p.f32(l.cos_outer);
  }
  // Version 2's sections after the lights (none of them is present in a version 1 file).
  for (const Float3& c : s.vertex_color) put(p, c);
  for (float a : s.vertex_alpha) p.f32(a);
  for (const TextureRecord& texture : s.textures) put_texture(p, texture);
  if (has_environment) put_texture(p, s.sky_environment);
  // Version 3's section after them.
  for (const Float3& v : s.tangents) put(p, v);
  for (float w : s.tangent_signs) p.f32(w);
  framing::finish_frame(kind, header, file);
  return file;
}

void write_scene_file(const std::string& path, const SceneFile& scene) {
  binary_io::write_whole_file(path, encode_scene(scene));
}

SceneFile read_scene(const uint8_t* data, size_t size, const std::string& name) {
  const framing::FramedView frame = framing::open_frame(data, size, kSceneKind, name);
  binary_io::LittleEndianReader h(frame.header, kSceneHeaderSize, name);
  h.skip(16);
  const uint32_t triangle_count = h.u32(), material_count = h.u32(), instance_count = h.u32(), node_count = h.u32();
  const uint32_t camera_count = h.u32(), light_count = h.u32(), page_count = h.u32(), texel_count = h.u32();
  const uint32_t partial_count = h.u32(), moved_count = h.u32(), probe_count = h.u32(), bvh_node_count = h.u32();
  const uint32_t leaf_count = h.u32();
  SceneFile s;
  s.bvh.stack_entries = h.u32();
  s.bvh.depth = h.u32();
  get(h, s.sky);
  const uint32_t environment = h.u32();
  s.texel_density = h.f32();
  get(h, s.probes.origin);
  get(h, s.probes.spacing);
  for (uint32_t& c : s.probes.counts) c = h.u32();
  const uint32_t texture_count = h.u32(), vertex_colors = h.u32();
  const uint32_t version = frame.version;
  const uint32_t tangents = h.u32();
  // Version 1 reserves offsets 132..143; version 2 uses the first two of them, version 3 all three.
  const uint32_t reserved[3] = {texture_count, vertex_colors, tangents};
  for (int k = version >= 3 ? 3 : version >= 2 ? 2 : 0; k < 3; ++k)
    if (reserved[k] != 0)
      throw FormatError(name + ": header: reserved field at offset " + std::to_string(132 + 4 * k) + " is " +
                        std::to_string(reserved[k]) + ", not 0");
  if (version < 2 && environment != 0)
    throw FormatError(name + ": header: sky environment " + std::to_string(environment) +
                      " is not 0 (environment maps are not stored by version 1)");
  if (environment > 1)
    throw FormatError(name + ": header: sky environment " + std::to_string(environment) + " is not 0 or 1");
  if (vertex_colors > 1)
    throw FormatError(name + ": header: vertex_colors " + std::to_string(vertex_colors) + " is not 0 or 1");
  // Colours are stored per triangle corner: a scene without triangles has none to flag (the writer
  // writes 0 there, so accepting 1 would read a file that does not re-encode to itself).
  if (vertex_colors == 1 && triangle_count == 0)
    throw FormatError(name + ": header: vertex_colors is 1 but the scene has no triangles");
  if (tangents > 1) throw FormatError(name + ": header: tangents " + std::to_string(tangents) + " is not 0 or 1");
  if (tangents == 1 && triangle_count == 0)
    throw FormatError(name + ": header: tangents is 1 but the scene has no triangles");
  if (triangle_count > kMaxSceneTriangles)
    throw FormatError(name + ": header: " + std::to_string(triangle_count) + " triangles exceed the limit of " +
                      std::to_string(kMaxSceneTriangles));
  // counts[0] * counts[1] fits 64 bits; times counts[2] only when the first product fits 32.
  const uint64_t xy = uint64_t(s.probes.counts[0]) * s.probes.counts[1];
  const bool probe_count_matches = (xy == 0 || s.probes.counts[2] == 0)
                                       ? probe_count == 0
                                       : xy <= 0xFFFFFFFFu && xy * s.probes.counts[2] == probe_count;
  if (!probe_count_matches)
    throw FormatError(name + ": header: probe count " + std::to_string(probe_count) + " is not " +
                      std::to_string(s.probes.counts[0]) + " x " + std::to_string(s.probes.counts[1]) + " x " +
                      std::to_string(s.probes.counts[2]));
  const uint64_t fixed = fixed_payload_bytes(triangle_count, bvh_node_count, leaf_count, page_count, texel_count,
                                             partial_count, moved_count, probe_count);
  const uint64_t material_bytes =
      kMinMaterialBytes + (version >= 2 ? kMaterialVersion2Bytes : 0) + (version >= 3 ? kMaterialVersion3Bytes : 0);
  const uint64_t version2_bytes = uint64_t(vertex_colors) * triangle_count * 3 * kVertexColorBytes +
                                  (uint64_t(texture_count) + environment) * kTextureHeaderBytes +
                                  uint64_t(tangents) * triangle_count * 3 * kTangentBytes;
  const uint64_t minimum = fixed + material_count * material_bytes + instance_count * kMinInstanceBytes +
                           node_count * kMinNodeBytes + camera_count * kMinCameraBytes + light_count * kMinLightBytes +
                           version2_bytes;
  if (frame.payload_size < minimum)
    throw FormatError(name + ": payload: " + std::to_string(frame.payload_size) +
                      " bytes, the header's counts need at least " + std::to_string(minimum));

  // The payload size now bounds every count, so these allocations are backed by real bytes.
  binary_io::LittleEndianReader p(frame.payload, size_t(frame.payload_size), name);
  SceneTriangles& t = s.triangles;
  // The large arrays in huge pages where the kernel allows (huge_pages.h): their first touch was
  // most of reading a scene.bin.
  for_each_triangle_array(t, [&](auto& values, size_t per_triangle) {
    resize_in_huge_pages(values, size_t(triangle_count) * per_triangle);
    p.words(values.data(), values.size());
  });
  resize_in_huge_pages(s.texels.triangle_texel_size, triangle_count);
  p.words(s.texels.triangle_texel_size.data(), s.texels.triangle_texel_size.size());
  resize_in_huge_pages(s.bvh.nodes, bvh_node_count);
  p.words(s.bvh.nodes.data(), s.bvh.nodes.size());  // members in the file's order (lo_x .. hi_z, child)
  resize_in_huge_pages(s.bvh.leaf_triangles, leaf_count);
  p.words(s.bvh.leaf_triangles.data(), s.bvh.leaf_triangles.size());
  s.texels.pages.resize(page_count);
  for (TexelPageRecord& page : s.texels.pages) {
    page.width = p.u32();
    page.height = p.u32();
    page.live_texels = p.u32();
  }
  std::vector<TexelRecord>& texels = s.texels.texels;
  resize_in_huge_pages(texels, texel_count);
  for (TexelRecord& r : texels) r.triangle = p.u32();
  for (TexelRecord& r : texels) {
    const uint32_t xy = p.u32();
    r.x = uint16_t(xy & 0xFFFFu);
    r.y = uint16_t(xy >> 16);
  }
  for (TexelRecord& r : texels) r.b1 = p.f32(), r.b2 = p.f32();
  s.texels.partial_coverage.resize(partial_count);
  for (PartialCoverageRecord& c : s.texels.partial_coverage) c.texel = p.u32(), c.coverage = p.f32();
  s.texels.moved.resize(moved_count);
  for (MovedTexelRecord& m : s.texels.moved) {
    m.texel = p.u32();
    get(p, m.position);
  }
  s.probes.probes.resize(probe_count);
  for (ProbeRecord& probe : s.probes.probes) {
    get(p, probe.position);
    probe.state = ProbeState(p.u32());
  }
  s.materials.resize(material_count);
  for (size_t i = 0; i < s.materials.size(); ++i) {
    MaterialRecord& m = s.materials[i];
    const std::string where = at(name, "material", i);
    m.name = get_name(p, where);
    get(p, m.base_color);
    m.metallic = p.f32();
    get(p, m.emission);
    m.double_sided = get_bool(p, where, "double_sided");
    m.base_color_texture.texture = int32_t(p.u32());
    m.emissive_texture.texture = int32_t(p.u32());
    if (version >= 2) {
      for (TextureBindingRecord* b : {&m.base_color_texture, &m.emissive_texture}) {
        b->tex_coord = p.u32();
        get(p, b->offset);
        b->rotation = p.f32();
        get(p, b->scale);
      }
      m.alpha_mode = AlphaMode(p.u32());
      m.alpha_cutoff = p.f32();
      m.base_alpha = p.f32();
      if (version >= 3) {
        TextureBindingRecord& b = m.normal_texture;
        b.texture = int32_t(p.u32());
        b.tex_coord = p.u32();
        get(p, b.offset);
        b.rotation = p.f32();
        get(p, b.scale);
        m.normal_scale = p.f32();
      }
    } else if (m.base_color_texture.texture != -1 || m.emissive_texture.texture != -1) {
      throw FormatError(where + "texture indices must be -1 in version 1 (textures are not stored by version 1)");
    }
  }
  s.instances.resize(instance_count);
  for (size_t i = 0; i < s.instances.size(); ++i) {
    InstanceRecord& r = s.instances[i];
    r.name = get_name(p, at(name, "instance", i));
    r.node = int32_t(p.u32());
    r.mesh = int32_t(p.u32());
    r.first_triangle = p.u32();
    r.triangle_count = p.u32();
    get(p, r.world);
    r.page = p.u32();
    r.x = p.u32(), r.y = p.u32(), r.width = p.u32(), r.height = p.u32();
    get(p, r.scale_offset);
  }
  s.nodes.resize(node_count);
  for (size_t i = 0; i < s.nodes.size(); ++i) {
    NodeRecord& n = s.nodes[i];
    const std::string where = at(name, "node", i);
    n.name = get_name(p, where);
    n.parent = int32_t(p.u32());
    n.mesh = int32_t(p.u32());
    n.light = int32_t(p.u32());
    n.camera = int32_t(p.u32());
    const uint32_t flags = p.u32();
    if (flags & ~(kNodeInScene | kNodeHasMatrix))
      throw FormatError(where + "undefined flag bits " + std::to_string(flags & ~(kNodeInScene | kNodeHasMatrix)));
    n.in_scene = flags & kNodeInScene;
    n.has_matrix = flags & kNodeHasMatrix;
    get(p, n.translation);
    get(p, n.rotation);
    get(p, n.scale);
    get(p, n.matrix);
  }
  s.cameras.resize(camera_count);
  for (size_t i = 0; i < s.cameras.size(); ++i) {
    CameraRecord& c = s.cameras[i];
    c.name = get_name(p, at(name, "camera", i));
    c.node = int32_t(p.u32());
    c.type = CameraType(p.u32());
    for (float* v : {&c.yfov, &c.aspect_ratio, &c.xmag, &c.ymag, &c.znear, &c.zfar}) *v = p.f32();
  }
  s.lights.resize(light_count);
  for (size_t i = 0; i < s.lights.size(); ++i) {
    LightRecord& l = s.lights[i];
    l.name = get_name(p, at(name, "light", i));
    l.node = int32_t(p.u32());
    l.type = LightType(p.u32());
    get(p, l.position);
    get(p, l.direction);
    get(p, l.intensity);
    l.cos_inner = p.f32();
    l.cos_outer = p.f32();
  }
  if (vertex_colors) {
    s.vertex_color.resize(size_t(triangle_count) * 3);
    s.vertex_alpha.resize(size_t(triangle_count) * 3);
    p.words(s.vertex_color.data(), s.vertex_color.size());
    p.words(s.vertex_alpha.data(), s.vertex_alpha.size());
  }
  // Each texture's pixels are checked against the bytes left before they are allocated.
  s.textures.reserve(texture_count);  // bounded by the payload size check above
  for (uint32_t i = 0; i < texture_count; ++i) s.textures.push_back(get_texture(p, at(name, "texture", i)));
  if (environment) s.sky_environment = get_texture(p, name + ": sky environment: ");
  if (tangents) {  // bounded by the payload size check above
    s.tangents.resize(size_t(triangle_count) * 3);
    s.tangent_signs.resize(size_t(triangle_count) * 3);
    p.words(s.tangents.data(), s.tangents.size());
    p.words(s.tangent_signs.data(), s.tangent_signs.size());
  }
  if (p.remaining() != 0)
    throw FormatError(name + ": payload: " + std::to_string(p.remaining()) + " bytes after the last " +
                      (version >= 2 ? "section" : "light"));
  validate_scene_file(s, name);
  if (version <= 3) refuse_version4_content(s, name, version);
  return s;
}

SceneFile read_scene_file(const std::string& path) {
  const std::vector<uint8_t> bytes = binary_io::read_whole_file(path);
  return read_scene(bytes.data(), bytes.size(), path);
}

}  // namespace exitance::formats
