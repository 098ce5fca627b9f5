#include "test_bundle.h"

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <unistd.h>

#include "exitance/formats/probes_file.h"
#include "exitance/formats/svo_file.h"

namespace exitance::test {
namespace fs = std::filesystem;

double page0_value(int channel, double x, double y) {
  switch (channel) {
    case 0: return 1.0 + x + 10.0 * y + 0.5 * x * y;
    case 1: return 2.0 * x + 0.5;
    default: return 3.0 - 0.25 * y + 0.125 * x * y;
  }
}

formats::LightmapImage make_page0() {
  formats::LightmapImage image;
  image.width = kPage0Width;
  image.height = kPage0Height;
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    auto& data = image.channels[names[c]];
    for (int y = 0; y < kPage0Height; ++y)
      for (int x = 0; x < kPage0Width; ++x) data.push_back(float(page0_value(c, x, y)));
  }
  image.channels["A"].assign(size_t(kPage0Width * kPage0Height), 1.0f);
  return image;
}

formats::LightmapImage make_page1() {
  formats::LightmapImage image;
  image.width = 4;
  image.height = 4;
  for (const char* name : {"R", "G", "B", "A"}) image.channels[name].assign(16, kPage1Value);
  image.channels["A"].assign(16, 1.0f);
  return image;
}

double linear_probe_field(int k, int c, const std::array<double, 3>& p) {
  return 0.1 * (k + 1) + 0.01 * c + 0.2 * p[0] - 0.3 * p[1] + 0.05 * (k % 3) * p[2] - 0.02 * c * p[0];
}

formats::ProbeGrid make_linear_probe_grid() {
  formats::ProbeGrid grid;
  grid.origin = {-1.0f, 0.0f, 2.0f};
  grid.spacing = {0.5f, 1.0f, 2.0f};
  grid.counts = {3, 2, 2};
  grid.probes.resize(12);
  for (uint32_t z = 0; z < 2; ++z)
    for (uint32_t y = 0; y < 2; ++y)
      for (uint32_t x = 0; x < 3; ++x) {
        formats::ProbeRecord& probe = grid.probes[grid.index(x, y, z)];
        const std::array<double, 3> p{grid.origin[0] + x * double(grid.spacing[0]), grid.origin[1] + y * double(grid.spacing[1]),
                                      grid.origin[2] + z * double(grid.spacing[2])};
        probe.position = {float(p[0]), float(p[1]), float(p[2])};
        for (int k = 0; k < 9; ++k)
          for (int c = 0; c < 3; ++c) probe.sh[size_t(k * 3 + c)] = float(linear_probe_field(k, c, p));
      }
  // A moved probe still counts as usable; its position differs, its coefficients stay on the field.
  grid.probes[grid.index(1, 1, 0)].state = formats::ProbeState::Moved;
  grid.probes[grid.index(1, 1, 0)].position[1] += 0.1f;
  return grid;
}

std::array<float, 3> svo_front(int node) { return {float(node + 1), float(2 * (node + 1)), 0.5f}; }
std::array<float, 3> svo_back(int node) { return {float(10 + node), 0.0f, 1.0f}; }

formats::SparseVoxelOctree make_test_octree() {
  using formats::SvoNode;
  formats::SparseVoxelOctree svo;
  svo.origin = {0, 0, 0};
  svo.size = 8;
  svo.depth = 2;
  svo.exitance_scale = kSvoExitanceScale;
  svo.level_begin = {0, 1, 3, 6};
  svo.nodes.resize(6);
  auto set = [&](int i, uint32_t first_child, uint32_t parent, uint8_t mask, uint8_t level) {
    SvoNode& n = svo.nodes[size_t(i)];
    n.first_child = first_child;
    n.parent = parent;
    n.child_mask = mask;
    n.level = level;
    n.flags = uint16_t(formats::kSvoFrontLit | (level == 2 ? formats::kSvoLeaf : 0));
    n.normal_oct = formats::encode_octahedral_normal(i == 5 ? std::array<float, 3>{1, 0, 0} : std::array<float, 3>{0, 1, 0});
    const auto front = svo_front(i), back = svo_back(i);
    for (int c = 0; c < 3; ++c) {
      n.exitance[c] = formats::float_to_half(front[c]);
      n.exitance[3 + c] = formats::float_to_half(back[c]);
    }
  };
  set(0, 1, formats::kSvoNoParent, 0x81, 0);
  set(1, 3, 0, 0x06, 1);
  set(2, 5, 0, 0x80, 1);
  set(3, 0, 1, 0, 2);
  set(4, 0, 1, 0, 2);
  set(5, 0, 2, 0, 2);
  return svo;
}

void write_bundle(const std::string& directory, const std::string& manifest_text,
                  const std::optional<formats::ProbeGrid>& probes, const std::optional<formats::SparseVoxelOctree>& svo) {
  fs::create_directories(directory);
  formats::write_lightmap_exr(directory + "/lightmap-0.exr", make_page0());
  formats::write_lightmap_exr(directory + "/lightmap-1.exr", make_page1());
  if (probes) formats::write_probes_file(directory + "/probes.bin", *probes);
  if (svo) formats::write_svo_file(directory + "/svo.bin", *svo);
  std::ofstream file(directory + "/manifest.json");
  file << manifest_text << "\n";
  if (!file) throw std::runtime_error("cannot write " + directory + "/manifest.json");
}

std::string fresh_directory(const std::string& name) {
  const fs::path path = fs::temp_directory_path() / ("exitance-formats-" + std::to_string(getpid()) + "-" + name);
  fs::remove_all(path);
  fs::create_directories(path);
  return path.string();
}

}  // namespace exitance::test
