// The C API (driven from C99 code) returns what the C++ API and the closed forms say, and reports
// errors as codes with a message instead of exceptions.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "c_api_walkthrough.h"
#include "exitance/loader/bundle.h"
#include "exitance/loader/exitance_loader.h"
#include "test_bundle.h"
#include "test_manifest.h"

namespace exitance::loader {
namespace {

TEST(LoaderCApi, MatchesTheClosedFormsThroughC) {
  const std::string dir = test::fresh_directory("c-api");
  const auto grid = test::make_linear_probe_grid();
  const auto svo = test::make_test_octree();
  test::write_bundle(dir, test::make_manifest(grid, svo).dump(2), grid, svo);

  const float point[3] = {-0.4f, 0.7f, 3.1f}, normal[3] = {0, 1, 0};
  const float u = 0.3f, v = 0.6f;
  CApiWalkthrough r;
  ASSERT_EQ(c_api_walkthrough(dir.c_str(), u, v, point, normal, 2, &r), 0) << r.open_error;
  EXPECT_EQ(r.missing_directory_error, EXITANCE_ERROR_IO);
  EXPECT_TRUE(r.missing_directory_handle_is_null);
  EXPECT_TRUE(r.missing_directory_message_names_it);
  EXPECT_EQ(r.null_argument_error, EXITANCE_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(r.last_error_after_success, EXITANCE_ERROR_NONE);

  EXPECT_EQ(r.page_count, 2u);
  EXPECT_EQ(r.instance_count, 2u);
  EXPECT_EQ(r.page0_width, uint32_t(test::kPage0Width));
  EXPECT_EQ(r.page0_height, uint32_t(test::kPage0Height));
  EXPECT_EQ(r.page0_channel_count, 4u);
  EXPECT_STREQ(r.page0_first_channel, "A");
  EXPECT_STREQ(r.instance0_name, "Floor");
  for (int i = 0; i < 4; ++i) EXPECT_EQ(r.instance0_scale_offset[i], test::kInstance0ScaleOffset[size_t(i)]);

  const auto& so = test::kInstance0ScaleOffset;
  const double x = (u * so[0] + so[2]) * test::kPage0Width - 0.5, y = (v * so[1] + so[3]) * test::kPage0Height - 0.5;
  EXPECT_EQ(r.lightmap_error, EXITANCE_ERROR_NONE);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.lightmap_rgb[c], test::page0_value(c, x, y), 1e-4);
  EXPECT_EQ(r.bad_instance_error, EXITANCE_ERROR_INVALID_ARGUMENT);

  ASSERT_TRUE(r.has_probes);
  EXPECT_EQ(r.probe_error, EXITANCE_ERROR_NONE);
  EXPECT_TRUE(r.probe_usable);
  for (int i = 0; i < 27; ++i)
    EXPECT_NEAR(r.probe_sh[i], test::linear_probe_field(i / 3, i % 3, {point[0], point[1], point[2]}), 1e-5);
  const Bundle bundle = Bundle::open(dir);
  const Rgb e = bundle.probe_irradiance_over_pi({point[0], point[1], point[2]}, {0, 1, 0}).irradiance_over_pi;
  for (int c = 0; c < 3; ++c) EXPECT_EQ(r.probe_irradiance[c], e[c]);
  EXPECT_EQ(r.probe_origin[0], -1.0f);

  ASSERT_TRUE(r.has_svo);
  EXPECT_EQ(r.svo_error, EXITANCE_ERROR_NONE);
  EXPECT_EQ(r.svo_depth, 2u);
  // (-0.4, 0.7, 3.1) lies outside the cube [0, 8]^3: not found, zeros.
  EXPECT_FALSE(r.svo_found);
  EXPECT_EQ(r.svo_rgb[0], 0.0f);
}

TEST(LoaderCApi, SvoLookupAndMissingProbesThroughC) {
  const std::string dir = test::fresh_directory("c-api-svo");
  const auto svo = test::make_test_octree();
  test::write_bundle(dir, test::make_manifest(std::nullopt, svo).dump(2), std::nullopt, svo);
  const float point[3] = {3, 1, 1}, normal[3] = {0, -1, 0};
  CApiWalkthrough r;
  ASSERT_EQ(c_api_walkthrough(dir.c_str(), 0.5f, 0.5f, point, normal, 2, &r), 0);
  EXPECT_FALSE(r.has_probes);
  EXPECT_EQ(r.no_probes_error, EXITANCE_ERROR_NOT_PRESENT);
  ASSERT_TRUE(r.has_svo);
  EXPECT_TRUE(r.svo_found);
  EXPECT_EQ(r.svo_level, 2u);
  const auto back = test::svo_back(3);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(r.svo_rgb[c], back[size_t(c)] * test::kSvoExitanceScale);
}

TEST(LoaderCApi, CorruptBundleIsAnInvalidFileError) {
  const std::string dir = test::fresh_directory("c-api-corrupt");
  test::write_bundle(dir, test::make_manifest(std::nullopt, std::nullopt).dump(2), std::nullopt, std::nullopt);
  { std::ofstream(dir + "/manifest.json") << "{\"format_version\": 1, \"pages\": 3}"; }
  ExitanceBundle* bundle = nullptr;
  EXPECT_EQ(exitance_bundle_open(dir.c_str(), &bundle), EXITANCE_ERROR_INVALID_FILE);
  EXPECT_EQ(bundle, nullptr);
  EXPECT_EQ(exitance_last_error(), EXITANCE_ERROR_INVALID_FILE);
  EXPECT_NE(std::strstr(exitance_last_error_message(), "pages: expected an array, got number"), nullptr)
      << exitance_last_error_message();
}

}  // namespace
}  // namespace exitance::loader
