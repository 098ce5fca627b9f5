// Light layers in a bundle's files (runtime/bundle/light_layer_pages.h, docs/bundle.md "Light
// layers"), without a device: what assemble_light_layer_pages writes reads back as the means it
// was given, layers several session layers add into are summed, a layer 0 on a page is left out of
// it, and a damaged file is one error naming the file and the problem (run under ASan+UBSan in CI).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/bundle/light_layer_pages.h"
#include "support/fresh_temp_dir.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

// Two pages of 4 x 3 and 2 x 2 pixels, five live texels, three estimate layers.
struct Fixture {
  TexelGBuffer gbuffer;
  LightmapEstimate estimate;
  Fixture() {
    gbuffer.pages = {{4, 3, std::vector<float>(12, 1.0f)}, {2, 2, std::vector<float>(4, 1.0f)}};
    const uint32_t where[5][3] = {{0, 0, 0}, {0, 3, 2}, {0, 1, 1}, {1, 0, 1}, {1, 1, 0}};
    for (const auto& w : where) {
      LiveTexel t;
      t.page = w[0], t.x = w[1], t.y = w[2];
      gbuffer.texels.push_back(t);
    }
    const size_t n = gbuffer.texels.size();
    estimate.texels.resize(n);
    estimate.light_layers = 3;
    estimate.light_sums.assign(3 * n * 3, 0.0);
    for (size_t i = 0; i < n; ++i) {
      estimate.texels[i].samples = uint32_t(4 + i);
      for (size_t k = 0; k < 3; ++k)
        for (size_t c = 0; c < 3; ++c)
          // Layer 2 lights page 0 only; the others every texel.
          if (k != 2 || gbuffer.texels[i].page == 0) estimate.light_sums[(k * n + i) * 3 + c] = double(estimate.texels[i].samples) * (0.25 * double(k + 1) + 0.01 * double(i) + 0.001 * double(c));
    }
  }
  double mean(size_t layer, size_t texel, size_t c) const {
    return estimate.light_sums[(layer * gbuffer.texels.size() + texel) * 3 + c] / estimate.texels[texel].samples;
  }
};

fs::path temp_dir() {
  static const fs::path dir = testing::fresh_temp_dir("light-layer-pages");
  return dir;
}

std::vector<std::string> write_pages(const std::vector<formats::LightmapImage>& pages, const std::string& name) {
  std::vector<std::string> files;
  for (size_t p = 0; p < pages.size(); ++p) {
    files.push_back((temp_dir() / (name + "-" + std::to_string(p) + ".exr")).string());
    formats::write_lightmap_exr(files.back(), pages[p]);
  }
  return files;
}

TEST(LightLayerPages, WrittenMeansReadBack) {
  const Fixture f;
  const std::vector<formats::LightmapImage> pages = assemble_light_layer_pages(f.gbuffer, f.estimate, {0, 1, 2});
  ASSERT_EQ(pages.size(), 2u);
  EXPECT_EQ(pages[0].channels.size(), 9u);  // three layers light page 0
  EXPECT_EQ(pages[1].channels.size(), 6u);  // layer 2 is 0 on page 1: left out
  EXPECT_EQ(pages[1].channels.count(light_layer_channel(2, 0)), 0u);
  const std::vector<float> means = read_light_layer_pages(write_pages(pages, "plain"), f.gbuffer, 3);
  const size_t n = f.gbuffer.texels.size();
  for (size_t k = 0; k < 3; ++k)
    for (size_t i = 0; i < n; ++i)
      for (size_t c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(means[(k * n + i) * 3 + c], float(f.mean(k, i, c))) << k << " " << i << " " << c;
  // The gutter (pixels of no live texel) is 0.
  EXPECT_EQ(pages[0].channels.at(light_layer_channel(0, 0))[1], 0.0f);
}

TEST(LightLayerPages, SessionLayersAddIntoTheBundlesLayer) {
  const Fixture f;
  // Session layers 1 and 2 are the bundle's layer 1 (an edit shared them differently).
  const std::vector<formats::LightmapImage> pages = assemble_light_layer_pages(f.gbuffer, f.estimate, {0, 1, 1});
  const std::vector<float> means = read_light_layer_pages(write_pages(pages, "summed"), f.gbuffer, 2);
  const size_t n = f.gbuffer.texels.size();
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c)
      EXPECT_FLOAT_EQ(means[(n + i) * 3 + c], float(f.mean(1, i, c) + f.mean(2, i, c))) << i << " " << c;
  EXPECT_THROW(assemble_light_layer_pages(f.gbuffer, f.estimate, {0, 1}), std::invalid_argument);
}

TEST(LightLayerPages, DamagedFilesAreOneErrorNamingTheFile) {
  const Fixture f;
  const std::vector<formats::LightmapImage> pages = assemble_light_layer_pages(f.gbuffer, f.estimate, {0, 1, 2});
  const struct {
    const char* name;
    std::function<void(std::vector<formats::LightmapImage>&)> damage;
    uint32_t count;
    const char* expected;
  } cases[] = {
      {"stray", [](auto& p) { p[0].channels["valid"] = p[0].channels.begin()->second; }, 3, "-0.exr: channel \"valid\" is not a light layer"},
      {"partial", [](auto& p) { p[1].channels.erase(light_layer_channel(1, 2)); }, 3, "-1.exr: layer 1 has 2 of its R, G, B channels"},
      {"beyond", [](auto&) {}, 2, "-0.exr: channel \"layer2.B\": layer 2 is not below the manifest's light_layers.count 2"},
      {"nan", [](auto& p) { p[1].channels[light_layer_channel(0, 1)][2] = NAN; }, 3, "-1.exr: channel \"layer0.G\" at pixel (0, 1): not finite"},
      {"size", [](auto& p) { p[1].width = 1, p[1].height = 4; }, 3, "-1.exr: 1x4 pixels, but scene.bin's atlas page 1 has 2x2"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    std::vector<formats::LightmapImage> damaged = pages;
    c.damage(damaged);
    const std::vector<std::string> files = write_pages(damaged, c.name);
    try {
      read_light_layer_pages(files, f.gbuffer, c.count);
      ADD_FAILURE() << "read";
    } catch (const std::runtime_error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(c.expected), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
  EXPECT_THROW(read_light_layer_pages({"only-one.exr"}, f.gbuffer, 3), std::runtime_error);
}

}  // namespace
}  // namespace exitance
