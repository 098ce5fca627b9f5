#include "exitance/bake/uvgen/scene_uv_generation.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace exitance {
namespace {

double local_triangle_area(const MeshWithoutLightmapUvs& mesh, uint32_t triangle) {
  const Vec3& a = mesh.positions[mesh.indices[3 * size_t(triangle)]];
  const Vec3& b = mesh.positions[mesh.indices[3 * size_t(triangle) + 1]];
  const Vec3& c = mesh.positions[mesh.indices[3 * size_t(triangle) + 2]];
  const double e1[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
  const double e2[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

// World area of an instance's triangles, summed as the atlas layout sums it.
double instance_world_area(const Scene& scene, uint32_t instance) {
  const Instance& in = scene.instances[instance];
  double area = 0;
  for (uint32_t t = in.first_triangle; t < in.first_triangle + in.triangle_count; ++t) area += triangle_area(scene, t);
  return area;
}

// UV area of an instance's triangles, summed as the atlas layout sums it.
double instance_uv_area(const Scene& scene, uint32_t instance) {
  const Instance& in = scene.instances[instance];
  double area = 0;
  for (uint32_t t = in.first_triangle; t < in.first_triangle + in.triangle_count; ++t) {
    const Vec2* uv = &scene.lightmap_uv[size_t(t) * 3];
    const Vec2 e1 = uv[1] - uv[0], e2 = uv[2] - uv[0];
    area += 0.5 * std::fabs(double(e1.x) * e2.y - double(e1.y) * e2.x);
  }
  return area;
}

void write_instance_uvs(Scene& scene, const MeshWithoutLightmapUvs::InstanceCorners& placement,
                        const std::vector<Vec2>& corner_uv) {
  const Instance& in = scene.instances[placement.instance];
  for (size_t c = 0; c < placement.corners.size(); ++c)
    scene.lightmap_uv[size_t(in.first_triangle) * 3 + c] = corner_uv[placement.corners[c]];
}

}  // namespace

std::vector<MeshUvReport> generate_missing_lightmap_uvs(Scene& scene, const std::vector<MeshWithoutLightmapUvs>& meshes,
                                                        double texel_density, int max_side_texels,
                                                        const std::function<void(double)>& progress) {
  size_t total_triangles = 0, done_triangles = 0;
  for (const MeshWithoutLightmapUvs& m : meshes) total_triangles += m.indices.size() / 3;
  std::vector<MeshUvReport> reports;
  for (const MeshWithoutLightmapUvs& mesh : meshes) {
    if (mesh.instances.empty()) continue;
    const auto start = std::chrono::steady_clock::now();
    const size_t triangles = mesh.indices.size() / 3;
    // Texels per mesh-local unit for the instance the layout will give the fewest texels per UV unit:
    // the layout gives density * sqrt(world area / UV area), and UV area is proportional to the
    // local area of the instance's triangles.
    double ratio = 1e300;
    for (const auto& placement : mesh.instances) {
      double local = 0;
      for (size_t c = 0; c < placement.corners.size(); c += 3) local += local_triangle_area(mesh, placement.corners[c] / 3);
      const double world = instance_world_area(scene, placement.instance);
      if (local > 0 && world > 0) ratio = std::min(ratio, std::sqrt(world / local));
    }
    if (ratio == 1e300) ratio = 1;
    UvGenerationSettings settings;
    settings.texels_per_unit = texel_density * ratio;
    settings.max_side_texels = max_side_texels;
    settings.progress = [&](double f) {
      if (progress && total_triangles)
        progress((double(done_triangles) + f * double(triangles)) / double(total_triangles));
    };
    // An instance that lost faces at import (degenerate in world space) measures its UV area on fewer
    // faces; if that leaves it fewer texels per UV unit than the packing, pack again at its density.
    GeneratedUvs uvs;
    for (int attempt = 0; attempt < 3; ++attempt) {
      uvs = generate_lightmap_uvs(mesh.positions, mesh.indices, settings);
      for (const auto& placement : mesh.instances) write_instance_uvs(scene, placement, uvs.corner_uv);
      const double side = std::max(uvs.stats.packed_width, uvs.stats.packed_height);
      double worst = 1;
      for (const auto& placement : mesh.instances) {
        const double world = instance_world_area(scene, placement.instance);
        const double uv = instance_uv_area(scene, placement.instance);
        if (world > 0 && uv > 0) worst = std::min(worst, texel_density * std::sqrt(world / uv) / side);
      }
      if (worst >= 0.98) break;  // the default gutter (3 texels) has that much to spare
      settings.texels_per_unit = uvs.stats.texels_per_unit * worst * 0.99;
    }
    done_triangles += triangles;
    MeshUvReport& report = reports.emplace_back();
    report.mesh = mesh.mesh;
    report.name = mesh.name;
    report.missing_set = mesh.missing_set;
    report.stats = uvs.stats;
    report.corner_uv = std::move(uvs.corner_uv);
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return reports;
}

}  // namespace exitance
