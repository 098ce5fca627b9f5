// Bundle::open on hand-built bundles, lookups against closed forms: bilinear of a polynomial
// texel field, trilinear of an affine SH field, unusable probes weighted out, E/pi of constant
// and linear radiance, SVO descent and side choice; and every broken bundle refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "byte_patching.h"
#include "exitance/formats/probes_file.h"
#include "exitance/formats/svo_file.h"
#include "exitance/loader/bundle.h"
#include "test_bundle.h"
#include "test_manifest.h"

namespace exitance::loader {
namespace {

using formats::FileAccessError;
using formats::FormatError;
using formats::ProbeState;
using nlohmann::json;
using test::expect_format_error;

std::string full_bundle(const std::string& name) {
  const std::string dir = test::fresh_directory(name);
  const auto grid = test::make_linear_probe_grid();
  const auto svo = test::make_test_octree();
  test::write_bundle(dir, test::make_manifest(grid, svo).dump(2), grid, svo);
  return dir;
}

std::string bundle_with(const std::string& name, const formats::ProbeGrid& grid) {
  const std::string dir = test::fresh_directory(name);
  test::write_bundle(dir, test::make_manifest(grid, std::nullopt).dump(2), grid, std::nullopt);
  return dir;
}

TEST(LoaderBundle, ListsPagesAndInstances) {
  const Bundle bundle = Bundle::open(full_bundle("lists"));
  ASSERT_EQ(bundle.pages().size(), 2u);
  EXPECT_EQ(bundle.pages()[0].width, 8u);
  EXPECT_EQ(bundle.page_image(1).width, 4);
  ASSERT_EQ(bundle.instances().size(), 2u);
  EXPECT_EQ(bundle.instances()[0].scale_offset, test::kInstance0ScaleOffset);
  EXPECT_TRUE(bundle.has_probes());
  EXPECT_TRUE(bundle.has_svo());
}

// Bilinear interpolation with texel centres at (i + 0.5) / w reproduces a + bx + cy + dxy exactly,
// so the expected value is the field at the (clamped) continuous texel coordinate.
TEST(LoaderBundle, LightmapIsBilinearWithTexelCentresAndClampToEdge) {
  const Bundle bundle = Bundle::open(full_bundle("bilinear"));
  const auto& so = test::kInstance0ScaleOffset;
  const std::array<float, 2> uvs[] = {{0.1f, 0.2f}, {0.37f, 0.81f}, {0.0f, 0.0f}, {1.0f, 1.0f},
                                      {-0.5f, 0.3f}, {1.5f, -1.0f}, {0.6f, 0.45f}, {-100.0f, 100.0f}};
  for (const auto& uv : uvs) {
    const double page_u = uv[0] * so[0] + so[2], page_v = uv[1] * so[1] + so[3];
    const double x = std::clamp(page_u * test::kPage0Width - 0.5, 0.0, double(test::kPage0Width - 1));
    const double y = std::clamp(page_v * test::kPage0Height - 0.5, 0.0, double(test::kPage0Height - 1));
    const Rgb e = bundle.lightmap(0, uv);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(e[c], test::page0_value(c, x, y), 1e-4) << "uv " << uv[0] << "," << uv[1] << " channel " << c;
  }
  // Texel centre (3, 1) of page 0 is page UV (3.5/8, 1.5/4): exactly that texel, row 1 from the top.
  const Rgb centre = bundle.lightmap(0, {float((3.5 / 8 - so[2]) / so[0]), float((1.5 / 4 - so[3]) / so[1])});
  EXPECT_NEAR(centre[0], test::page0_value(0, 3, 1), 1e-4);
  const Rgb wall = bundle.lightmap(1, {0.3f, 0.9f});
  for (float v : wall) EXPECT_FLOAT_EQ(v, test::kPage1Value);
}

TEST(LoaderBundle, LightmapRefusesBadArguments) {
  const Bundle bundle = Bundle::open(full_bundle("lightmap-args"));
  EXPECT_THROW(bundle.lightmap(2, {0, 0}), std::out_of_range);
  EXPECT_THROW(bundle.lightmap(0, {std::nanf(""), 0}), std::invalid_argument);
  EXPECT_THROW(bundle.lightmap(0, {0, INFINITY}), std::invalid_argument);
  EXPECT_NO_THROW(bundle.lightmap(0, {3e38f, -3e38f}));
}

// Trilinear interpolation reproduces an affine field exactly; outside the grid it clamps.
TEST(LoaderBundle, ProbeShIsTrilinearInTheGrid) {
  const Bundle bundle = Bundle::open(full_bundle("trilinear"));
  const Point3 points[] = {{-0.8f, 0.3f, 2.5f}, {-0.1f, 0.9f, 3.9f}, {0.0f, 1.0f, 4.0f}, {-1.0f, 0.0f, 2.0f}, {-0.5f, 0.5f, 3.0f}};
  for (const Point3& p : points) {
    const ProbeShResult r = bundle.probe_sh(p);
    ASSERT_TRUE(r.usable);
    for (int k = 0; k < 9; ++k)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(r.sh[k][c], test::linear_probe_field(k, c, {p[0], p[1], p[2]}), 1e-5) << "k " << k << " c " << c;
  }
  const ProbeShResult outside = bundle.probe_sh({5.0f, -3.0f, 2.5f});  // clamps to x = 0, y = 0
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(outside.sh[k][1], test::linear_probe_field(k, 1, {0.0, 0.0, 2.5}), 1e-5);
}

formats::ProbeGrid constant_grid(float value) {
  formats::ProbeGrid grid = test::make_linear_probe_grid();
  for (auto& probe : grid.probes)
    for (size_t i = 0; i < probe.sh.size(); ++i) probe.sh[i] = value * float(1 + i % 5);
  return grid;
}

TEST(LoaderBundle, UnusableProbesAreWeightedOut) {
  formats::ProbeGrid grid = constant_grid(0.5f);
  const float garbage = 1000.0f;
  for (uint32_t x : {1u, 2u}) {
    auto& probe = grid.probes[grid.index(x, 0, 0)];
    probe.state = x == 1 ? ProbeState::Invalid : ProbeState::Skipped;
    probe.sh.fill(garbage);
  }
  const Bundle bundle = Bundle::open(bundle_with("weighted-out", grid));
  // Points in both cells next to the unusable probes, and one exactly on the Invalid probe (every
  // usable corner then has trilinear weight 0: the usable corners are averaged).
  const Point3 points[] = {{-0.7f, 0.2f, 2.4f}, {-0.2f, 0.1f, 2.1f}, {0.0f, 0.0f, 2.0f}, {-0.5f, 0.0f, 2.0f}};
  for (const Point3& p : points) {
    const ProbeShResult r = bundle.probe_sh(p);
    ASSERT_TRUE(r.usable);
    for (int i = 0; i < 27; ++i) EXPECT_NEAR(r.sh[i / 3][i % 3], 0.5f * float(1 + i % 5), 1e-5) << "coefficient " << i;
  }
}

// With an affine field and one Invalid corner, the result is the usable corners' trilinear weights
// renormalised: sum(w f) / sum(w) over the seven usable corners.
TEST(LoaderBundle, RenormalisedWeightsOfAnAffineField) {
  formats::ProbeGrid grid = test::make_linear_probe_grid();
  grid.probes[grid.index(1, 1, 1)].state = ProbeState::Invalid;
  grid.probes[grid.index(1, 1, 1)].sh.fill(-77.0f);
  const Bundle bundle = Bundle::open(bundle_with("renormalised", grid));
  const Point3 p{-0.3f, 0.6f, 3.0f};  // cell x 1..2, y 0..1, z 0..1; t = (0.4, 0.6, 0.5)
  const double t[3] = {0.4, 0.6, 0.5};
  double weight_sum = 0, expected = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = (corner >> 2) & 1;
    if (dx == 0 && dy == 1 && dz == 1) continue;  // grid point (1, 1, 1): the Invalid probe
    const double w = (dx ? t[0] : 1 - t[0]) * (dy ? t[1] : 1 - t[1]) * (dz ? t[2] : 1 - t[2]);
    const std::array<double, 3> q{-1.0 + 0.5 * (1 + dx), double(dy), 2.0 + 2.0 * dz};
    weight_sum += w;
    expected += w * test::linear_probe_field(4, 2, q);
  }
  EXPECT_NEAR(bundle.probe_sh(p).sh[4][2], expected / weight_sum, 1e-5);
}

TEST(LoaderBundle, CellWithoutUsableProbesIsFlagged) {
  formats::ProbeGrid grid = constant_grid(1.0f);
  for (uint32_t z = 0; z < 2; ++z)
    for (uint32_t y = 0; y < 2; ++y)
      for (uint32_t x = 0; x < 2; ++x) grid.probes[grid.index(x, y, z)].state = ProbeState::Invalid;
  const Bundle bundle = Bundle::open(bundle_with("no-usable", grid));
  const ProbeShResult none = bundle.probe_sh({-0.75f, 0.5f, 3.0f});
  EXPECT_FALSE(none.usable);
  for (const Rgb& c : none.sh) EXPECT_EQ(c, (Rgb{0, 0, 0}));
  const ProbeIrradianceResult e = bundle.probe_irradiance_over_pi({-0.75f, 0.5f, 3.0f}, {0, 1, 0});
  EXPECT_FALSE(e.usable);
  EXPECT_EQ(e.irradiance_over_pi, (Rgb{0, 0, 0}));
  EXPECT_TRUE(bundle.probe_sh({-0.25f, 0.5f, 3.0f}).usable);  // next cell has the x = 2 probes
}

// Constant radiance L: c0 = L * sqrt(4 pi), E/pi = L for every normal. Linear radiance
// L(w) = w . d (band 1 only): E(n)/pi = 2/3 n . d.
TEST(LoaderBundle, ProbeIrradianceOverPiMatchesClosedForms) {
  const float kSqrt4Pi = 3.5449077f, kY1 = 0.488602512f;
  const Rgb radiance{0.5f, 1.0f, 2.0f};
  const std::array<float, 3> d{0.3f, -0.5f, 0.8f};
  formats::ProbeGrid grid = test::make_linear_probe_grid();
  for (auto& probe : grid.probes) {
    probe.sh.fill(0.0f);
    for (int c = 0; c < 3; ++c) {
      probe.sh[size_t(c)] = radiance[c] * kSqrt4Pi;
      // projection of w_y, w_z, w_x on Y1-1, Y10, Y11 is 4 pi / 3 * 0.4886; channel 0 only
      if (c == 0) {
        probe.sh[3 * 1] += d[1] * kY1 * 4.18879020f;
        probe.sh[3 * 2] += d[2] * kY1 * 4.18879020f;
        probe.sh[3 * 3] += d[0] * kY1 * 4.18879020f;
      }
    }
  }
  const Bundle bundle = Bundle::open(bundle_with("irradiance", grid));
  const Point3 normals[] = {{0, 1, 0}, {0, 0, -3}, {1, 1, 1}, {-0.2f, 0.1f, 0.9f}};
  for (const Point3& n : normals) {
    const double length = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
    const double n_dot_d = (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / length;
    const ProbeIrradianceResult e = bundle.probe_irradiance_over_pi({-0.6f, 0.4f, 3.3f}, n);
    ASSERT_TRUE(e.usable);
    EXPECT_NEAR(e.irradiance_over_pi[0], radiance[0] + 2.0 / 3.0 * n_dot_d, 1e-5);
    EXPECT_NEAR(e.irradiance_over_pi[1], radiance[1], 1e-5);
    EXPECT_NEAR(e.irradiance_over_pi[2], radiance[2], 1e-5);
  }
  EXPECT_THROW(bundle.probe_irradiance_over_pi({0, 0, 0}, {0, 0, 0}), std::invalid_argument);
  EXPECT_THROW(bundle.probe_sh({0, std::nanf(""), 0}), std::invalid_argument);
  EXPECT_THROW(bundle.svo_exitance({0, 0, 0}, 0, {0, 1, 0}), std::logic_error);  // no SVO in this bundle
}

TEST(LoaderBundle, SvoExitanceDescendsAndPicksTheFacingSide) {
  const Bundle bundle = Bundle::open(full_bundle("svo"));
  const float s = test::kSvoExitanceScale;
  auto scaled = [&](std::array<float, 3> v) { return Rgb{v[0] * s, v[1] * s, v[2] * s}; };
  struct Case {
    Point3 point;
    uint32_t level;
    Point3 normal;
    int node;
    uint32_t reached;
    bool back;
  };
  const Case cases[] = {
      {{3, 1, 1}, 2, {0, 1, 0}, 3, 2, false},    // leaf 3 ([2,4]x[0,2]x[0,2]), front faces +Y
      {{3, 1, 1}, 2, {0, -1, 0}, 3, 2, true},    // same leaf seen from below
      {{1, 3, 1}, 9, {0.1f, 1, 0}, 4, 2, false}, // level beyond the depth stops at the leaves
      {{1, 1, 1}, 2, {0, 1, 0}, 1, 1, false},    // octant 0 of node 1 has no child: stays at level 1
      {{3, 1, 1}, 1, {0, 1, 0}, 1, 1, false},    // asked for level 1
      {{5, 1, 1}, 2, {0, 1, 0}, 0, 0, false},    // root octant 1 is empty: the root
      {{7, 7, 7}, 2, {-1, 0, 0}, 5, 2, true},    // node 5's normal is +X
      {{8, 8, 8}, 2, {1, 0, 0}, 5, 2, false},    // the far corner belongs to the last cell
  };
  for (const Case& c : cases) {
    const SvoExitanceResult r = bundle.svo_exitance(c.point, c.level, c.normal);
    ASSERT_TRUE(r.found);
    EXPECT_EQ(r.node, uint32_t(c.node));
    EXPECT_EQ(r.level, c.reached);
    EXPECT_EQ(r.back_side, c.back);
    EXPECT_EQ(r.exitance, scaled(c.back ? test::svo_back(c.node) : test::svo_front(c.node)));
  }
  EXPECT_FALSE(bundle.svo_exitance({9, 1, 1}, 2, {0, 1, 0}).found);
  EXPECT_FALSE(bundle.svo_exitance({1, -0.01f, 1}, 2, {0, 1, 0}).found);
  EXPECT_THROW(bundle.svo_exitance({1, 1, 1}, 2, {0, 0, 0}), std::invalid_argument);
  EXPECT_THROW(bundle.svo_exitance({INFINITY, 1, 1}, 2, {0, 1, 0}), std::invalid_argument);
}

// ---- broken bundles ----

void write_text(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// A valid full bundle whose manifest is edited by `edit`.
std::string bundle_with_manifest(const std::string& name, void (*edit)(json&)) {
  const std::string dir = full_bundle(name);
  json manifest = test::make_manifest(test::make_linear_probe_grid(), test::make_test_octree());
  edit(manifest);
  write_text(dir + "/manifest.json", manifest.dump());
  return dir;
}

TEST(LoaderBundle, MissingPiecesAreAccessErrors) {
  EXPECT_THROW(Bundle::open(test::fresh_directory("missing") + "/nothing-here"), FileAccessError);
  const std::string empty = test::fresh_directory("no-manifest");
  try {
    Bundle::open(empty);
    FAIL();
  } catch (const FileAccessError& e) {
    EXPECT_NE(std::string(e.what()).find("manifest.json: cannot open"), std::string::npos) << e.what();
  }
  std::string dir = full_bundle("no-page");
  std::filesystem::remove(dir + "/lightmap-1.exr");
  expect_format_error([&] { Bundle::open(dir); }, "lightmap-1.exr: missing (named by manifest.json pages[1])");
  EXPECT_THROW(Bundle::open(dir), FileAccessError);
  dir = full_bundle("no-probes");
  std::filesystem::remove(dir + "/probes.bin");
  expect_format_error([&] { Bundle::open(dir); }, "probes.bin: missing (named by manifest.json probes.file)");
}

struct ManifestCase {
  const char* name;
  void (*edit)(json&);
  const char* expected;
};

const ManifestCase kManifestCases[] = {
    {"page width", [](json& j) { j["pages"][0]["width"] = 9; }, "lightmap-0.exr: 8 x 4 texels, manifest.json pages[0] says 9 x 4"},
    {"listed channel", [](json& j) { j["pages"][1]["channels"].push_back("direct.R"); }, "channel direct.R listed in manifest.json pages[1] is missing"},
    {"page index", [](json& j) { j["instances"][0]["page"] = 5; }, "manifest.json: instances[0].page: 5 is not a page (2 pages)"},
    {"wrong type", [](json& j) { j["instances"] = "none"; }, "manifest.json: instances: expected an array, got string"},
    {"probe counts", [](json& j) { j["probes"]["counts"] = {3, 2, 3}; }, "does not match manifest.json probes: counts 3 x 2 x 2 vs 3 x 2 x 3"},
    {"probe origin", [](json& j) { j["probes"]["origin"][1] = 0.5; }, "does not match manifest.json probes: origin"},
    {"probe spacing", [](json& j) { j["probes"]["spacing"][0] = 0.25; }, "does not match manifest.json probes: spacing"},
    {"svo depth", [](json& j) { j["svo"]["depth"] = 3; }, "does not match manifest.json svo: depth 2 vs 3"},
    {"svo bounds", [](json& j) { j["svo"]["bounds"][1] = {8, 8, 9}; }, "svo: bounds are not the octree's cube"},
    {"probes file is the svo", [](json& j) { j["probes"]["file"] = "svo.bin"; }, "svo.bin: not this kind of file (wrong magic)"},
    {"page file is the manifest", [](json& j) { j["pages"][0]["file"] = "manifest.json"; }, "manifest.json"},
    {"version", [](json& j) { j["format_version"] = 7; }, "manifest.json: format version 7 is newer than this loader (1)"},
};

TEST(LoaderBundle, ManifestErrorsAndMismatchesAreRefusedByName) {
  for (const ManifestCase& c : kManifestCases) {
    SCOPED_TRACE(c.name);
    const std::string dir = bundle_with_manifest(std::string("manifest-") + c.name, c.edit);
    expect_format_error([&] { Bundle::open(dir); }, c.expected);
  }
}

TEST(LoaderBundle, CorruptBinaryFilesAreRefused) {
  std::string dir = full_bundle("corrupt-svo");
  {
    std::fstream file(dir + "/svo.bin", std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(100);
    file.put(char(0x5A));
  }
  expect_format_error([&] { Bundle::open(dir); }, "svo.bin: payload: checksum");
  dir = full_bundle("corrupt-exr");
  write_text(dir + "/lightmap-0.exr", "not an EXR file");
  try {
    Bundle::open(dir);
    FAIL();
  } catch (const FileAccessError& e) {
    FAIL() << "a malformed EXR is not an access error: " << e.what();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("lightmap-0.exr"), std::string::npos) << e.what();
  }
  dir = full_bundle("no-blue");
  formats::LightmapImage page = test::make_page0();
  page.channels.erase("B");
  formats::write_lightmap_exr(dir + "/lightmap-0.exr", page);
  expect_format_error([&] { Bundle::open(dir); }, "lightmap-0.exr: channel B missing");
}

TEST(LoaderBundle, BundleWithoutProbesOrSvoLoads) {
  const std::string dir = test::fresh_directory("lightmaps-only");
  test::write_bundle(dir, test::make_manifest(std::nullopt, std::nullopt).dump(2), std::nullopt, std::nullopt);
  const Bundle bundle = Bundle::open(dir);
  EXPECT_FALSE(bundle.has_probes());
  EXPECT_FALSE(bundle.has_svo());
  EXPECT_EQ(bundle.probe_grid(), nullptr);
  EXPECT_THROW(bundle.probe_sh({0, 0, 0}), std::logic_error);
}

}  // namespace
}  // namespace exitance::loader
