// What an engine does with a bundle, through the loader's C++ API only: list the atlas pages and
// instances, read each instance's lightmap at its chart centre, the probes' E/pi facing up (+Y,
// glTF's up) at the grid centre, and the SVO's exitance at a few points and levels.
#include <cstdio>
#include <exception>

#include "exitance/loader/bundle.h"

using exitance::loader::Bundle;

namespace {

// TEXCOORD_1 of the chart centre: the centre of the instance's texel rectangle when the manifest
// has one, mapped back through uv * s + o; else (0.5, 0.5).
std::array<float, 2> chart_centre_uv(const Bundle& bundle, const exitance::loader::InstanceInfo& instance) {
  const auto& s = instance.scale_offset;
  if (!instance.rect || s[0] == 0 || s[1] == 0) return {0.5f, 0.5f};
  const auto& page = bundle.pages()[instance.page];
  const auto& r = *instance.rect;
  const float page_u = (float(r[0]) + 0.5f * float(r[2])) / float(page.width);
  const float page_v = (float(r[1]) + 0.5f * float(r[3])) / float(page.height);
  return {(page_u - s[2]) / s[0], (page_v - s[3]) / s[1]};
}

void print_lightmaps(const Bundle& bundle) {
  std::printf("pages: %zu\n", bundle.pages().size());
  for (size_t p = 0; p < bundle.pages().size(); ++p) {
    const auto& page = bundle.pages()[p];
    std::printf("  page %zu: %s %u x %u, channels:", p, page.file.c_str(), page.width, page.height);
    for (const auto& channel : page.channels) std::printf(" %s", channel.c_str());
    std::printf("\n");
  }
  std::printf("instances: %zu\n", bundle.instances().size());
  for (size_t i = 0; i < bundle.instances().size(); ++i) {
    const auto& instance = bundle.instances()[i];
    const auto uv = chart_centre_uv(bundle, instance);
    const auto e = bundle.lightmap(i, uv);
    std::printf("  instance %zu \"%s\" node %u mesh %u page %u scale_offset [%g %g %g %g]: E/pi at uv (%.4f, %.4f) = (%g, %g, %g)\n",
                i, instance.name.c_str(), instance.node, instance.mesh, instance.page, instance.scale_offset[0],
                instance.scale_offset[1], instance.scale_offset[2], instance.scale_offset[3], uv[0], uv[1], e[0], e[1],
                e[2]);
  }
}

void print_probes(const Bundle& bundle) {
  const auto* grid = bundle.probe_grid();
  if (!grid) {
    std::printf("probes: none\n");
    return;
  }
  exitance::loader::Point3 centre{};
  for (int a = 0; a < 3; ++a) centre[a] = grid->origin[a] + 0.5f * grid->spacing[a] * float(grid->counts[a] - 1);
  const auto up = bundle.probe_irradiance_over_pi(centre, {0, 1, 0});
  std::printf("probes: %u x %u x %u, E/pi facing +Y at the grid centre (%g, %g, %g) = (%g, %g, %g)%s\n", grid->counts[0],
              grid->counts[1], grid->counts[2], centre[0], centre[1], centre[2], up.irradiance_over_pi[0],
              up.irradiance_over_pi[1], up.irradiance_over_pi[2], up.usable ? "" : " (no usable probe there)");
}

void print_svo(const Bundle& bundle) {
  const auto* svo = bundle.octree();
  if (!svo) {
    std::printf("svo: none\n");
    return;
  }
  std::printf("svo: depth %u, %zu nodes, cube (%g, %g, %g) + %g\n", svo->depth, svo->nodes.size(), svo->origin[0],
              svo->origin[1], svo->origin[2], svo->size);
  const float fractions[] = {0.25f, 0.5f, 0.75f};  // points on the cube's diagonal
  for (float f : fractions) {
    const exitance::loader::Point3 p{svo->origin[0] + f * svo->size, svo->origin[1] + f * svo->size,
                                     svo->origin[2] + f * svo->size};
    for (uint32_t level : {0u, svo->depth / 2, svo->depth}) {
      const auto m = bundle.svo_exitance(p, level, {0, 1, 0});
      if (!m.found) {
        std::printf("  (%g, %g, %g) level %u: outside\n", p[0], p[1], p[2], level);
        continue;
      }
      std::printf("  (%g, %g, %g) level %u: reached level %u, %s side, exitance (%g, %g, %g)\n", p[0], p[1], p[2], level,
                  m.level, m.back_side ? "back" : "front", m.exitance[0], m.exitance[1], m.exitance[2]);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s BUNDLE_DIR\n", argv[0]);
    return 2;
  }
  try {
    const Bundle bundle = Bundle::open(argv[1]);
    std::printf("bundle %s (%s)\n", argv[1], bundle.manifest().generator.c_str());
    print_lightmaps(bundle);
    print_probes(bundle);
    print_svo(bundle);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "exitance_loader_sample: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
