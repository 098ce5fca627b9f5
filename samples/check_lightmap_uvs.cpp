// check_lightmap_uvs FILE.gltf...: reads glTF files back and checks, per mesh,
// what the baker relies on and the generator promises: TEXCOORD_1 inside [0,1]²,
// no two triangles overlapping in TEXCOORD_1, charts (triangle groups connected through
// corners equal in POSITION and TEXCOORD_1)
// at least kLightmapChartPadding apart by their bounding rectangles, unit NORMALs,
// and counter-clockwise winding on the NORMAL side. Exit status 1 on any failure.
// It shares no code with the generator's own checks beyond the padding constant.
#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "lightmap_chart_packer.h"

namespace {

using Vec2 = std::array<float, 2>;
using Vec3f = std::array<float, 3>;

struct MeshTriangles {
  std::vector<std::array<Vec2, 3>> uv;  // TEXCOORD_1 corners
  std::vector<std::array<Vec3f, 3>> position;
  std::vector<Vec3f> normal;                      // NORMAL of the first corner
  std::vector<std::array<size_t, 3>> vertexKey;  // ids of distinct (POSITION, TEXCOORD_1), to find charts
};

// The accessor's bytes as an array of T: tight or strided, as written by any tool
// whose component type is T's.
template <typename T>
std::vector<T> readAccessor(const tinygltf::Model& model, int index) {
  const tinygltf::Accessor& accessor = model.accessors[size_t(index)];
  const tinygltf::BufferView& view = model.bufferViews[size_t(accessor.bufferView)];
  const unsigned char* base = model.buffers[size_t(view.buffer)].data.data() + view.byteOffset + accessor.byteOffset;
  const size_t components = size_t(tinygltf::GetNumComponentsInType(uint32_t(accessor.type)));
  const size_t stride = view.byteStride ? view.byteStride : components * sizeof(T);
  std::vector<T> values(accessor.count * components);
  for (size_t i = 0; i < accessor.count; ++i) std::memcpy(&values[i * components], base + i * stride, components * sizeof(T));
  return values;
}

// True when the two triangles' interiors overlap by more than `epsilon` (separating
// axis test over the six edge normals); triangles that only share edges do not.
bool interiorsOverlap(const std::array<Vec2, 3>& a, const std::array<Vec2, 3>& b, float epsilon) {
  for (const auto* t : {&a, &b})
    for (int e = 0; e < 3; ++e) {
      const Vec2 p = (*t)[size_t(e)], q = (*t)[size_t((e + 1) % 3)];
      const Vec2 axis{p[1] - q[1], q[0] - p[0]};
      const float len = std::hypot(axis[0], axis[1]);
      if (len == 0.0f) continue;
      auto project = [&](const std::array<Vec2, 3>& tri, float& lo, float& hi) {
        lo = hi = (tri[0][0] * axis[0] + tri[0][1] * axis[1]) / len;
        for (const Vec2& v : tri) {
          const float d = (v[0] * axis[0] + v[1] * axis[1]) / len;
          lo = std::min(lo, d), hi = std::max(hi, d);
        }
      };
      float aLo, aHi, bLo, bHi;
      project(a, aLo, aHi);
      project(b, bLo, bHi);
      if (aHi <= bLo + epsilon || bHi <= aLo + epsilon) return false;
    }
  return true;
}

size_t findRoot(std::vector<size_t>& parent, size_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

int checkMesh(const std::string& label, const MeshTriangles& mesh) {
  int failures = 0;
  auto fail = [&](const std::string& what) {
    if (failures++ < 5) std::printf("  %s: %s\n", label.c_str(), what.c_str());
  };
  const size_t count = mesh.uv.size();
  for (size_t t = 0; t < count; ++t) {
    for (const Vec2& uv : mesh.uv[t])
      if (uv[0] < 0.0f || uv[0] > 1.0f || uv[1] < 0.0f || uv[1] > 1.0f) fail("TEXCOORD_1 outside [0,1]");
    const auto& p = mesh.position[t];
    const Vec3f e1{p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const Vec3f e2{p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    const Vec3f g{e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const Vec3f& n = mesh.normal[t];
    if (std::abs(std::hypot(n[0], n[1], n[2]) - 1.0f) > 1e-4f) fail("NORMAL not unit length");
    if (!(g[0] * n[0] + g[1] * n[1] + g[2] * n[2] > 0.0f)) fail("triangle " + std::to_string(t) + " winds against NORMAL");
  }

  // Charts: triangles joined through shared vertices.
  std::vector<size_t> parent(count);
  std::iota(parent.begin(), parent.end(), size_t{0});
  std::vector<size_t> ownerOfVertex;
  for (size_t t = 0; t < count; ++t)
    for (size_t key : mesh.vertexKey[t]) {
      if (key >= ownerOfVertex.size()) ownerOfVertex.resize(key + 1, SIZE_MAX);
      if (ownerOfVertex[key] == SIZE_MAX) ownerOfVertex[key] = t;
      else parent[findRoot(parent, t)] = findRoot(parent, ownerOfVertex[key]);
    }
  std::vector<std::array<float, 4>> bounds(count, {2.0f, 2.0f, -1.0f, -1.0f});  // per root: min u,v, max u,v
  for (size_t t = 0; t < count; ++t) {
    auto& b = bounds[findRoot(parent, t)];
    for (const Vec2& uv : mesh.uv[t])
      b = {std::min(b[0], uv[0]), std::min(b[1], uv[1]), std::max(b[2], uv[0]), std::max(b[3], uv[1])};
  }
  std::vector<std::array<float, 4>> charts;
  for (size_t t = 0; t < count; ++t)
    if (findRoot(parent, t) == t) charts.push_back(bounds[t]);
  const float gap = exitance::samples::kLightmapChartPadding - 1e-5f;
  for (size_t i = 0; i < charts.size(); ++i)
    for (size_t j = i + 1; j < charts.size(); ++j) {
      const auto &a = charts[i], &b = charts[j];
      if (!(a[2] + gap <= b[0] || b[2] + gap <= a[0] || a[3] + gap <= b[1] || b[3] + gap <= a[1]))
        fail("charts " + std::to_string(i) + " and " + std::to_string(j) + " closer than the padding");
    }

  // Triangle overlap, through a uniform grid over UV space.
  constexpr int kGrid = 128;
  std::vector<std::vector<size_t>> cells(kGrid * kGrid);
  auto cellOf = [](float x) { return std::clamp(int(x * kGrid), 0, kGrid - 1); };
  for (size_t t = 0; t < count; ++t) {
    const auto& tri = mesh.uv[t];
    const int x0 = cellOf(std::min({tri[0][0], tri[1][0], tri[2][0]})), x1 = cellOf(std::max({tri[0][0], tri[1][0], tri[2][0]}));
    const int y0 = cellOf(std::min({tri[0][1], tri[1][1], tri[2][1]})), y1 = cellOf(std::max({tri[0][1], tri[1][1], tri[2][1]}));
    bool reported = false;  // one report per triangle, not one per shared cell
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        for (size_t other : cells[size_t(y * kGrid + x)])
          if (!reported && interiorsOverlap(tri, mesh.uv[other], 1e-6f)) {
            fail("triangles " + std::to_string(other) + " and " + std::to_string(t) + " overlap in TEXCOORD_1");
            reported = true;
          }
        cells[size_t(y * kGrid + x)].push_back(t);
      }
  }
  return failures;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: check_lightmap_uvs FILE.gltf...\n");
    return 2;
  }
  int failures = 0;
  for (int arg = 1; arg < argc; ++arg) {
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string error, warning;
    if (!loader.LoadASCIIFromFile(&model, &error, &warning, argv[arg])) {
      std::printf("%s: cannot load: %s\n", argv[arg], error.c_str());
      ++failures;
      continue;
    }
    size_t triangles = 0;
    for (size_t m = 0; m < model.meshes.size(); ++m) {
      MeshTriangles mesh;
      std::map<std::array<float, 5>, size_t> cornerIds;
      for (const tinygltf::Primitive& primitive : model.meshes[m].primitives) {
        const std::vector<float> uv = readAccessor<float>(model, primitive.attributes.at("TEXCOORD_1"));
        const std::vector<float> position = readAccessor<float>(model, primitive.attributes.at("POSITION"));
        const std::vector<float> normal = readAccessor<float>(model, primitive.attributes.at("NORMAL"));
        if (model.accessors[size_t(primitive.indices)].componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
          std::printf("%s: mesh %zu: indices are not UNSIGNED_INT\n", argv[arg], m);
          ++failures;
          continue;
        }
        const std::vector<uint32_t> indices = readAccessor<uint32_t>(model, primitive.indices);
        for (size_t i = 0; i + 2 < indices.size(); i += 3) {
          std::array<Vec2, 3> tuv;
          std::array<Vec3f, 3> tp;
          std::array<size_t, 3> keys;
          for (size_t c = 0; c < 3; ++c) {
            const size_t v = indices[i + c];
            tuv[c] = {uv[2 * v], uv[2 * v + 1]};
            tp[c] = {position[3 * v], position[3 * v + 1], position[3 * v + 2]};
            // A chart may fold (a crease duplicates vertices for their normals): corners
            // equal in position and lightmap UV join triangles, whatever their index.
            const std::array<float, 5> corner{tp[c][0], tp[c][1], tp[c][2], tuv[c][0], tuv[c][1]};
            keys[c] = cornerIds.try_emplace(corner, cornerIds.size()).first->second;
          }
          const size_t v0 = indices[i];
          mesh.uv.push_back(tuv);
          mesh.position.push_back(tp);
          mesh.normal.push_back({normal[3 * v0], normal[3 * v0 + 1], normal[3 * v0 + 2]});
          mesh.vertexKey.push_back(keys);
        }
      }
      triangles += mesh.uv.size();
      failures += checkMesh(std::string(argv[arg]) + " mesh " + std::to_string(m) + " '" + model.meshes[m].name + "'",
                            mesh);
    }
    std::printf("%s: %zu meshes, %zu triangles checked\n", argv[arg], model.meshes.size(), triangles);
  }
  std::printf(failures ? "FAILED: %d problems\n" : "all checks passed\n", failures);
  return failures ? 1 : 0;
}
