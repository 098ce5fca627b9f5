// scene.bin: what the runtime needs to re-light a bundle with no offline stage (layout in
// formats/scene_format.md): the world-space triangle soup, materials, instances with their world
// transforms and atlas rectangles, the glTF node hierarchy, cameras, punctual lights, the sky, the
// compact texel G-buffer, the probe grid layout and the BVH in the GPU's BVH4 layout.
//
// Plain records, standard library only: the runtime converts them to and from its Scene,
// TexelGBuffer and atlas types (runtime/include/exitance/runtime/scene_file_conversion.h).
// Writers validate first, so a file they write is always one the readers accept; readers validate
// every field and the cross references (indices in range, BVH a tree over every triangle, texels
// inside their page and on a triangle of an instance on that page) before returning.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "exitance/formats/format_error.h"
#include "exitance/formats/probe_grid.h"

namespace exitance::formats {

inline constexpr char kSceneMagic[8] = {'E', 'X', 'S', 'C', 'E', 'N', 'E', '\0'};
constexpr uint32_t kSceneFormatVersion = 4;        // what writers write
constexpr uint32_t kOldestSceneFormatVersion = 1;  // readers accept 1 .. kSceneFormatVersion
constexpr uint32_t kSceneHeaderSize = 160;
// Fixed record sizes (bytes) of the payload's arrays; scene_format.md has the layouts.
constexpr uint32_t kSceneBvhNodeSize = 112;
constexpr uint32_t kSceneTexelSize = 16;  // over the three per-texel arrays
constexpr uint32_t kScenePartialCoverageSize = 8;
constexpr uint32_t kSceneMovedTexelSize = 16;
// Refused above these: a corrupt count must not become a huge allocation, and the BVH's leaf words
// hold a 29-bit first slot (formats/scene_format.md, "BVH").
constexpr uint64_t kMaxSceneTriangles = uint64_t(1) << 28;
constexpr uint32_t kMaxScenePageSize = 65535;                 // texel x and y are stored as u16
constexpr uint64_t kMaxSceneAtlasTexels = uint64_t(1) << 30;  // sum of width * height over all pages
constexpr uint32_t kMaxSceneNameBytes = 65535;
constexpr uint32_t kMaxSceneNodeDepth = 256;  // deepest node depth (root 0), as the glTF importer
constexpr uint32_t kMaxSceneTextureSize = 65535;  // texture width and height (version 2)

// BVH4 child words, as runtime/.../core/bvh4.h and shaders/include/bvh.glsl use them.
constexpr uint32_t kSceneBvhEmptyChild = 0xFFFFFFFFu;
constexpr uint32_t kSceneBvhLeafBit = 0x80000000u;  // leaf: bit 31 | first slot << 2 | (count - 1)

using Float2 = std::array<float, 2>;
using Float3 = std::array<float, 3>;
using Double16 = std::array<double, 16>;  // 4x4 matrix, column-major as glTF

inline constexpr Double16 kIdentityMatrix{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

// Unindexed triangle soup in world space: the per-corner arrays hold 3 entries per triangle.
struct SceneTriangles {
  std::vector<Float3> positions;
  std::vector<Float3> normals;      // shading normals
  std::vector<Float2> lightmap_uv;  // the UV set the atlas was laid out from
  std::vector<Float2> uv0;          // TEXCOORD_0 (zeros when absent)
  std::vector<uint32_t> material;   // per triangle
  std::vector<uint32_t> instance;   // per triangle
  size_t count() const { return material.size(); }
};

// A texture exactly as the lighting stage samples it (runtime Texture): linear float RGB after the
// importer's sRGB decode, optional linear alpha, wrap modes. Row 0 = top. Version 2.
enum class TextureWrap : uint32_t { Repeat = 0, ClampToEdge = 1, MirroredRepeat = 2 };

struct TextureRecord {
  uint32_t width = 0, height = 0;
  TextureWrap wrap_s = TextureWrap::Repeat, wrap_t = TextureWrap::Repeat;
  std::vector<float> rgb;    // width * height * 3
  std::vector<float> alpha;  // width * height in [0, 1], or empty
};

// A material's texture: index into SceneFile::textures (-1: none), which TEXCOORD_n it reads and
// its KHR_texture_transform (uv' = T * R * S * uv).
struct TextureBindingRecord {
  int32_t texture = -1;
  uint32_t tex_coord = 0;  // 0 or 1
  Float2 offset{0, 0};
  float rotation = 0;
  Float2 scale{1, 1};
};

enum class AlphaMode : uint32_t { Opaque = 0, Mask = 1, Blend = 2 };

struct MaterialRecord {
  std::string name;
  Float3 base_color{1, 1, 1};  // linear factor
  float metallic = 1.0f;
  Float3 emission{0, 0, 0};  // emissiveFactor * KHR_materials_emissive_strength
  bool double_sided = false;
  // Version 2 (version 1 files read back as no textures, OPAQUE, cutoff 0.5, base alpha 1).
  TextureBindingRecord base_color_texture;
  TextureBindingRecord emissive_texture;
  AlphaMode alpha_mode = AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;
  float base_alpha = 1.0f;  // baseColorFactor[3]
  // Version 3 (older files read back as none): glTF normalTexture, linear RGB (no sRGB decode), and
  // its scale (tangent-space x, y multiplied by it).
  TextureBindingRecord normal_texture;
  float normal_scale = 1.0f;
};

struct InstanceRecord {
  std::string name;
  int32_t node = -1;  // glTF node index (-1: no node, e.g. a scene built in code)
  int32_t mesh = -1;  // glTF mesh index
  uint32_t first_triangle = 0;
  uint32_t triangle_count = 0;
  Double16 world = kIdentityMatrix;               // node-to-world transform the triangles were flattened with
  uint32_t page = 0;                              // atlas page
  uint32_t x = 0, y = 0, width = 0, height = 0;   // chart rectangle in texels (inside the padding)
  std::array<float, 4> scale_offset{1, 1, 0, 0};  // page_uv = lightmap_uv * s + o
};

struct NodeRecord {
  std::string name;
  int32_t parent = -1;      // -1: a root (or a node outside the default scene)
  int32_t mesh = -1;        // glTF mesh index
  int32_t light = -1;       // index into SceneFile::lights
  int32_t camera = -1;      // index into SceneFile::cameras
  bool in_scene = false;    // reached from the default scene's roots
  bool has_matrix = false;  // local transform is `matrix`, else translation * rotation * scale
  std::array<double, 3> translation{0, 0, 0};
  std::array<double, 4> rotation{0, 0, 0, 1};  // quaternion x, y, z, w as glTF stores it
  std::array<double, 3> scale{1, 1, 1};
  Double16 matrix = kIdentityMatrix;
};

enum class CameraType : uint32_t { Perspective = 0, Orthographic = 1 };

struct CameraRecord {
  std::string name;
  int32_t node = -1;  // the node that places it
  CameraType type = CameraType::Perspective;
  float yfov = 0, aspect_ratio = 0;  // perspective (aspect_ratio 0: not given)
  float xmag = 0, ymag = 0;          // orthographic
  float znear = 0, zfar = 0;         // perspective zfar 0: infinite
};

enum class LightType : uint32_t { Point = 0, Spot = 1, Directional = 2 };

struct LightRecord {
  std::string name;   // the glTF light's name
  int32_t node = -1;  // the node that places it
  LightType type = LightType::Point;
  Float3 position{0, 0, 0};
  Float3 direction{0, 0, -1};  // unit, the direction light travels
  Float3 intensity{1, 1, 1};   // W/sr (point, spot) or W/m^2 (directional), RGB
  float cos_inner = 1.0f, cos_outer = 0.0f;
};

// The compact texel G-buffer (scene_format.md, "Texels"): per live texel its triangle, texel
// coordinates and barycentrics on the triangle; per triangle the world texel size; coverage 1
// except for the texels listed in `partial_coverage`. Position, normals, albedo and instance are
// derived on load (runtime/include/exitance/runtime/texel_surface.h); texels the unocclude step
// moved off that point keep their exact position in `moved`.
struct TexelPageRecord {
  uint32_t width = 0, height = 0;
  uint32_t live_texels = 0;  // texels of this page in TexelGBufferRecords::texels, after earlier pages'
};

struct TexelRecord {
  uint32_t triangle = 0;
  uint16_t x = 0, y = 0;  // column, row (row 0 = top)
  float b1 = 0, b2 = 0;   // barycentric weights of corners 1 and 2
};

struct PartialCoverageRecord {
  uint32_t texel = 0;  // index into TexelGBufferRecords::texels
  float coverage = 0;  // fraction of the texel covered by charts, in (0, 1) (the lightmap's A channel)
};

struct MovedTexelRecord {
  uint32_t texel = 0;  // index into TexelGBufferRecords::texels
  Float3 position{0, 0, 0};
};

struct TexelGBufferRecords {
  std::vector<TexelPageRecord> pages;
  std::vector<TexelRecord> texels;         // page-major; Morton order (x bits even, y bits odd) inside a page
  std::vector<float> triangle_texel_size;  // per scene triangle: world-space edge of one of its texels
  std::vector<PartialCoverageRecord> partial_coverage;  // ascending texel index; every other texel: 1
  std::vector<MovedTexelRecord> moved;                  // ascending texel index
};

// One node of the GPU BVH4 (runtime/.../core/bvh4.h): child i's box and child word.
struct BvhNodeRecord {
  float lo_x[4], hi_x[4], lo_y[4], hi_y[4], lo_z[4], hi_z[4];
  uint32_t child[4];
};
static_assert(sizeof(BvhNodeRecord) == kSceneBvhNodeSize, "scene.bin BVH node record is 112 bytes");

// One level over the world-space triangles (a two-level layout, per mesh plus instances, will be a
// later format version). Nodes depth-first, nodes[0] the root; leaf slots hold scene triangle indices.
struct SceneBvh {
  std::vector<BvhNodeRecord> nodes;
  std::vector<uint32_t> leaf_triangles;
  uint32_t stack_entries = 1;  // traversal stack bound
  uint32_t depth = 0;          // inner-node levels (0: empty root)
};

struct SceneFile {
  SceneTriangles triangles;
  std::vector<MaterialRecord> materials;
  std::vector<InstanceRecord> instances;
  std::vector<NodeRecord> nodes;  // every glTF node, in glTF order
  std::vector<CameraRecord> cameras;
  std::vector<LightRecord> lights;
  Float3 sky{0, 0, 0};         // constant sky radiance
  TextureRecord sky_environment;  // equirectangular radiance map replacing `sky`; width 0: none (version 2)
  std::vector<TextureRecord> textures;  // version 2
  // COLOR_0 per corner (3 per triangle), or both empty: no vertex colours (version 2).
  std::vector<Float3> vertex_color;
  std::vector<float> vertex_alpha;
  // Per corner (3 per triangle), or both empty: world-space tangent (unit, or zero on corners no
  // normal map reads) and its handedness w = +1 or -1, bitangent = w * cross(normal, tangent) (version 3).
  std::vector<Float3> tangents;
  std::vector<float> tangent_signs;
  float texel_density = 0;     // lightmap texels per scene unit
  TexelGBufferRecords texels;  // includes the atlas page sizes
  // Probe positions and states only (SH coefficients are not stored: they read back as zero).
  // counts {0, 0, 0} and no probes: the bake has no probe grid.
  ProbeGrid probes = no_probe_grid();
  SceneBvh bvh;

  static ProbeGrid no_probe_grid() {
    ProbeGrid grid;
    grid.spacing = {0, 0, 0};
    return grid;
  }
};

// Morton code of a texel inside its page (16-bit x and y interleaved, x in the even bits).
inline uint32_t texel_morton_code(uint32_t x, uint32_t y) {
  auto spread = [](uint32_t v) {
    v &= 0xFFFF;
    v = (v | (v << 8)) & 0x00FF00FF;
    v = (v | (v << 4)) & 0x0F0F0F0F;
    v = (v | (v << 2)) & 0x33333333;
    v = (v | (v << 1)) & 0x55555555;
    return v;
  };
  return spread(x) | (spread(y) << 1);
}

// Throws FormatError naming the first record or field that is wrong (the checks are listed in
// scene_format.md, "What readers refuse").
void validate_scene_file(const SceneFile& scene, const std::string& name_for_errors);

// The exact bytes of scene.bin; throws FormatError if the scene is invalid. format_version 1
// (or 2) writes the old layout (tests, fixtures) and refuses a scene with anything only a later version holds.
std::vector<uint8_t> encode_scene(const SceneFile& scene, uint32_t format_version = kSceneFormatVersion);
void write_scene_file(const std::string& path, const SceneFile& scene);

// Throws FormatError (FileAccessError when the file cannot be read at all).
SceneFile read_scene(const uint8_t* data, size_t size, const std::string& name_for_errors);
SceneFile read_scene_file(const std::string& path);

}  // namespace exitance::formats
