// Lightmap UV generation time (bake/uvgen) on a synthetic torus of about N triangles, welded or with
// every triangle's vertices split as some exporters write them (bench/results/uvgen.md).
//   bench_uvgen [--triangles N] [--split] [--density T] [--search-max-triangles N] [--dump UVS.txt]
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "exitance/bake/uvgen/lightmap_uv_generation.h"

int main(int argc, char** argv) {
  size_t triangles = 1'000'000;
  bool split = false;
  double density = 64;
  CLI::App app{"lightmap UV generation time on a torus"};
  app.add_option("--triangles", triangles, "about this many triangles");
  app.add_flag("--split", split, "every triangle with vertices of its own");
  app.add_option("--density", density, "texels per unit (the torus is 2.7 units wide)");
  exitance::UvGenerationSettings settings;
  app.add_option("--search-max-triangles", settings.layout_search_max_triangles,
                 "meshes up to this many triangles search for a tighter layout (UvGenerationSettings)");
  std::string dump;
  app.add_option("--dump", dump, "write the generated UVs (chart u0 v0 u1 v1 u2 v2 per triangle) to this file");
  CLI11_PARSE(app, argc, argv);

  const int nv = std::max(3, int(std::sqrt(double(triangles) / 4))), nu = 2 * nv;
  std::vector<exitance::Vec3> grid;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double u = 2 * std::numbers::pi * i / nu, w = 2 * std::numbers::pi * j / nv, r = 1 + 0.35 * std::cos(w);
      grid.push_back({float(r * std::cos(u)), float(0.35 * std::sin(w)), float(-r * std::sin(u))});
    }
  std::vector<uint32_t> indices;
  auto at = [&](int i, int j) { return uint32_t(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i)
      indices.insert(indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
  std::vector<exitance::Vec3> positions = grid;
  if (split) {
    positions.clear();
    for (uint32_t& index : indices) {
      positions.push_back(grid[index]);
      index = uint32_t(positions.size() - 1);
    }
  }
  settings.texels_per_unit = density;
  const auto start = std::chrono::steady_clock::now();
  const exitance::GeneratedUvs uvs = exitance::generate_lightmap_uvs(positions, indices, settings);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const exitance::UvGenerationStats& s = uvs.stats;
  std::printf("triangles %zu (%s vertices) seconds %.2f charts %zu (lscm %zu, planar %zu) utilization %.3f "
              "area distortion max %.3f mean %.3f angle distortion max %.3f mean %.3f packed %dx%d at %.1f texels/unit\n",
              s.triangles, split ? "split" : "shared", seconds, s.charts, s.lscm_charts, s.planar_charts, s.utilization,
              s.max_area_distortion, s.mean_area_distortion, s.max_angle_distortion, s.mean_angle_distortion,
              s.packed_width, s.packed_height, s.texels_per_unit);
  if (!dump.empty()) {
    FILE* f = std::fopen(dump.c_str(), "w");
    if (!f) return 1;
    for (size_t t = 0; t < uvs.triangle_chart.size(); ++t) {
      std::fprintf(f, "%u", uvs.triangle_chart[t]);
      for (size_t k = 0; k < 3; ++k) std::fprintf(f, " %.6f %.6f", uvs.corner_uv[3 * t + k].x, uvs.corner_uv[3 * t + k].y);
      std::fprintf(f, "\n");
    }
    std::fclose(f);
  }
  return 0;
}
