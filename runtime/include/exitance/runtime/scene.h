// The lighting stage's view of a scene: world-space triangle soup, materials, lights, sky.
// Produced by the offline stage (bake/gltf_import), consumed by every backend.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "exitance/runtime/matrix4d.h"  // Matrix4d
#include "exitance/runtime/vec_math.h"

namespace exitance {

// Linear RGB texture, row 0 = top (glTF UV (0,0) is the top-left corner).
struct Texture {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  // width * height * 3, linear
  // width * height coverage in [0, 1] (glTF alpha is linear); empty when the image has no alpha or
  // no material reads it (only the base colour of a MASK or BLEND material does).
  std::vector<float> alpha;
  enum class Wrap { Repeat, ClampToEdge, MirroredRepeat };
  Wrap wrap_s = Wrap::Repeat;
  Wrap wrap_t = Wrap::Repeat;
};

// KHR_texture_transform: uv' = T * R * S * uv
struct TextureTransform {
  Vec2 offset{0, 0};
  float rotation = 0;
  Vec2 scale{1, 1};
  int tex_coord = 0;  // which TEXCOORD_n the texture reads (after override)
};

struct TextureBinding {
  int texture = -1;  // index into Scene::textures, -1 = none
  TextureTransform transform;
};

struct Material {
  std::string name;
  Vec3 base_color{1, 1, 1};  // linear factor
  TextureBinding base_color_texture;
  float metallic = 1.0f;  // glTF default
  Vec3 emission{0, 0, 0};  // emissiveFactor * KHR_materials_emissive_strength
  TextureBinding emissive_texture;
  bool double_sided = false;
  // glTF alphaMode: coverage = base_alpha * base colour texture alpha. MASK: rays pass where
  // coverage < alpha_cutoff. BLEND: stochastic transparency, a ray passes with probability
  // 1 - coverage (alpha_coverage.h).
  enum class AlphaMode { Opaque, Mask, Blend };
  AlphaMode alpha_mode = AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;
  float base_alpha = 1.0f;  // baseColorFactor[3]
  // glTF normalTexture (linear RGB, tangent space: n = normalize((2 rgb - 1) * (scale, scale, 1))).
  // Not used by the lighting stage, which lights the interpolated normal as engines do with
  // directional lightmaps; exitance-view evaluates the L1 SH layers at the mapped normal.
  TextureBinding normal_texture;
  float normal_scale = 1.0f;
};

struct PunctualLight {
  enum class Type { Point, Spot, Directional };
  Type type = Type::Point;
  std::string name;
  Vec3 position{0, 0, 0};
  Vec3 direction{0, 0, -1};  // direction the light travels (node -Z in world space)
  Vec3 intensity{1, 1, 1};   // colour * intensity: W/sr for point/spot, W/m^2 for directional
  float cos_inner = 1.0f;    // spot only
  float cos_outer = 0.0f;    // spot only
  int node = -1;             // the glTF node that places it (Scene::nodes), -1 when built in code
};

struct Sky {
  Vec3 constant{0, 0, 0};
  // Optional equirectangular radiance map (row 0 = +Y pole). Multiplies nothing: if present it replaces `constant`.
  Texture environment;
  bool has_environment() const { return environment.width > 0; }
};


// One mesh instance (a glTF node with a mesh). Triangles [first_triangle, first_triangle + triangle_count).
struct Instance {
  int node = -1;
  std::string name;
  int mesh = -1;
  uint32_t first_triangle = 0;
  uint32_t triangle_count = 0;
  Matrix4d world = kIdentityMatrix4d;  // node-to-world transform the triangles were flattened with
};

// A glTF node, kept so edits can address nodes by name and the runtime can recompose world
// transforms: Scene::nodes[i] is glTF node i.
struct SceneNode {
  std::string name;
  int parent = -1;          // -1: a root of the default scene, or a node outside it
  int mesh = -1;            // glTF mesh index
  int light = -1;           // index into Scene::lights (the light this node places)
  int camera = -1;          // index into Scene::cameras (the camera this node places)
  bool in_scene = false;    // reached from the default scene's roots
  bool has_matrix = false;  // local transform is `matrix`; else translation * rotation * scale
  std::array<double, 3> translation{0, 0, 0};
  std::array<double, 4> rotation{0, 0, 0, 1};  // quaternion x, y, z, w, as written in the file
  std::array<double, 3> scale{1, 1, 1};
  Matrix4d matrix = kIdentityMatrix4d;
};

// A glTF camera placed by a node (not used for lighting; kept for viewers and edits).
struct SceneCamera {
  enum class Type { Perspective, Orthographic };
  std::string name;  // the glTF camera's name
  int node = -1;
  Type type = Type::Perspective;
  float yfov = 0, aspect_ratio = 0;  // perspective; aspect_ratio 0 = not given
  float xmag = 0, ymag = 0;          // orthographic
  float znear = 0, zfar = 0;         // perspective zfar 0 = infinite
};

// Unindexed triangle soup; every per-vertex array holds 3 entries per triangle.
struct Scene {
  std::vector<Vec3> positions;        // world space
  std::vector<Vec3> normals;          // world space shading normals, unit length
  std::vector<Vec2> uv0;              // TEXCOORD_0 (zeros when absent)
  std::vector<Vec2> lightmap_uv;      // TEXCOORD_1 (or TEXCOORD_0 with --uv 0)
  // COLOR_0 (linear), which multiplies the base colour and its alpha: per corner, or both empty
  // when no primitive has COLOR_0 (corners of primitives without it are white, alpha 1).
  std::vector<Vec3> vertex_color;
  std::vector<float> vertex_alpha;
  // Tangent frames for normal maps: per corner, or both empty when no material has a normal map.
  // World-space unit tangent (the glTF TANGENT attribute, else generated from the normal map's UV
  // derivatives: tangent_frames.h; zero on corners of primitives whose material has no normal map)
  // and handedness w = +1 or -1: bitangent = w * cross(normal, tangent).
  std::vector<Vec3> tangents;
  std::vector<float> tangent_signs;
  std::vector<uint32_t> triangle_material;
  std::vector<uint32_t> triangle_instance;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Instance> instances;
  std::vector<PunctualLight> lights;
  Sky sky;
  std::vector<SceneNode> nodes;      // every glTF node, in glTF order (empty for scenes built in code)
  std::vector<SceneCamera> cameras;  // one per node that places a camera

  size_t triangle_count() const { return triangle_material.size(); }
};

// World-space area and front-side unit normal (counter-clockwise winding) of triangle t.
inline float triangle_area(const Scene& scene, size_t t) {
  const Vec3* p = &scene.positions[t * 3];
  return 0.5f * length(cross(p[1] - p[0], p[2] - p[0]));
}
inline Vec3 triangle_normal(const Scene& scene, size_t t) {
  const Vec3* p = &scene.positions[t * 3];
  return normalize(cross(p[1] - p[0], p[2] - p[0]));
}

}  // namespace exitance
