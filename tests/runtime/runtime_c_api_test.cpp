// libexitance_runtime's C API (exitance/runtime/exitance_runtime.h), linked as the shared library
// an engine links: a C99 walkthrough, errors as codes with one-line messages, failed calls that
// change nothing, a written bundle the loader opens, and light paths switched between refreshes. The
// bundle is baked by the `bake` program, so this test links nothing of the offline stage.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/loader/exitance_loader.h"
#include "exitance/runtime/exitance_runtime.h"
#include "exitance/runtime/exitance_runtime_vulkan.h"

extern "C" int runtime_c_walkthrough(const char* bundle, const char* output, char* message, size_t message_size);

namespace {

namespace fs = std::filesystem;

const fs::path& bundle() {
  static const fs::path path = [] {
    const fs::path dir = fs::temp_directory_path() / ("exitance-runtime-c-api-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string command = std::string(EXITANCE_BAKE) + " " + EXITANCE_SAMPLE_DIR +
                                "/cornell_room.gltf -o " + (dir / "cornell.bake").string() +
                                " --backend cpu --spp 1 --texel-density 4 --probe-spp 16 2>/dev/null";
    if (std::system(command.c_str()) != 0) throw std::runtime_error("bake failed: " + command);
    return dir / "cornell.bake";
  }();
  return path;
}

bool has_device() {
  ExitanceRuntime* rt = nullptr;
  const ExitanceRuntimeError code = exitance_runtime_open(bundle().c_str(), nullptr, &rt);
  exitance_runtime_release(rt);
  return code != EXITANCE_RUNTIME_NO_DEVICE;
}

TEST(RuntimeCApi, WalkthroughFromCWritesABundleTheLoaderOpens) {
  if (!has_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path output = bundle().parent_path() / "refreshed.bake";
  char message[512] = "";
  ASSERT_EQ(runtime_c_walkthrough(bundle().c_str(), output.c_str(), message, sizeof message), 0) << message;
  ExitanceBundle* loaded = nullptr;
  ASSERT_EQ(exitance_bundle_open(output.c_str(), &loaded), EXITANCE_ERROR_NONE) << exitance_last_error_message();
  float rgb[3];
  EXPECT_EQ(exitance_bundle_lightmap(loaded, 0, 0.5f, 0.5f, rgb), EXITANCE_ERROR_NONE);
  EXPECT_TRUE(std::isfinite(rgb[0]) && std::isfinite(rgb[1]) && std::isfinite(rgb[2]));
  EXPECT_EQ(exitance_bundle_has_probes(loaded), 1);
  exitance_bundle_release(loaded);
}

TEST(RuntimeCApi, ErrorsAreCodesWithOneLineMessages) {
  ExitanceRuntime* rt = reinterpret_cast<ExitanceRuntime*>(0x1);
  EXPECT_EQ(exitance_runtime_open(nullptr, nullptr, &rt), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_EQ(rt, nullptr);
  EXPECT_EQ(exitance_runtime_last_error(), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_EQ(std::string(exitance_runtime_last_error_message()), "exitance_runtime_open: bundle is NULL");
  const std::string missing = (bundle().parent_path() / "missing.bake").string();
  const ExitanceRuntimeError code = exitance_runtime_open(missing.c_str(), nullptr, &rt);
  if (code == EXITANCE_RUNTIME_NO_DEVICE) GTEST_SKIP() << "no Vulkan device";
  EXPECT_EQ(code, EXITANCE_RUNTIME_BAD_BUNDLE);
  const std::string message = exitance_runtime_last_error_message();
  EXPECT_NE(message.find("missing.bake/manifest.json: cannot read the manifest"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
  EXPECT_EQ(exitance_runtime_refresh(nullptr, 16, 0, nullptr), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  const ExitanceRuntimeOptions bad_layers{-1, 0, 0, 2};
  EXPECT_EQ(exitance_runtime_open(bundle().c_str(), &bad_layers, &rt), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_EQ(rt, nullptr);
  EXPECT_EQ(std::string(exitance_runtime_last_error_message()), "exitance_runtime_open: options->light_layers_off must be 0 or 1");
  exitance_runtime_release(nullptr);  // ignored
}

TEST(RuntimeCApi, FailedCallsChangeNothing) {
  if (!has_device()) GTEST_SKIP() << "no Vulkan device";
  ExitanceRuntime* rt = nullptr;
  ASSERT_EQ(exitance_runtime_open(bundle().c_str(), nullptr, &rt), EXITANCE_RUNTIME_OK);
  ExitanceRefreshReport report{};
  ASSERT_EQ(exitance_runtime_refresh(rt, 0, 2, &report), EXITANCE_RUNTIME_OK);
  EXPECT_EQ(report.samples_per_texel, 2u);

  EXPECT_EQ(exitance_runtime_refresh(rt, std::numeric_limits<double>::quiet_NaN(), 0, &report),
            EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_EQ(exitance_runtime_refresh(rt, 0, 0, &report), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_EQ(exitance_runtime_apply_edits(rt, "{\"edits\": [{\"light\": \"NoSuchLamp\", \"intensity\": 1}]}"),
            EXITANCE_RUNTIME_BAD_EDIT);
  EXPECT_NE(std::string(exitance_runtime_last_error_message()).find("exitance_runtime_apply_edits: edits[0]"),
            std::string::npos)
      << exitance_runtime_last_error_message();
  EXPECT_EQ(exitance_runtime_apply_edits(rt, "{\"edits\": [{\"sky\": [0.1, 0.2]}]}"), EXITANCE_RUNTIME_BAD_EDIT);
  EXPECT_EQ(exitance_runtime_apply_edits(rt, "not json"), EXITANCE_RUNTIME_BAD_EDIT);
  ExitanceRuntimePageInfo page{};
  ASSERT_EQ(exitance_runtime_page_info(rt, 0, &page), EXITANCE_RUNTIME_OK);
  EXPECT_EQ(exitance_runtime_page_info(rt, exitance_runtime_page_count(rt), &page), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  std::vector<float> rgb(size_t(page.width) * page.height * 3);
  EXPECT_EQ(exitance_runtime_read_page(rt, 0, rgb.data(), page.width + 1, page.height), EXITANCE_RUNTIME_INVALID_ARGUMENT);

  // Still 2 samples: the next refresh adds the third.
  ASSERT_EQ(exitance_runtime_refresh(rt, 0, 3, &report), EXITANCE_RUNTIME_OK);
  EXPECT_EQ(report.samples_added, 1u);
  ASSERT_EQ(exitance_runtime_read_page(rt, 0, rgb.data(), page.width, page.height), EXITANCE_RUNTIME_OK);
  size_t lit = 0;
  for (float v : rgb) {
    ASSERT_TRUE(std::isfinite(v) && v >= 0);
    lit += v > 0;
  }
  EXPECT_GT(lit, rgb.size() / 4);
  exitance_runtime_release(rt);
}

// exitance_runtime_set_light_paths: on changes what the next refresh adds (the Cornell room's panel
// starts subpaths), off after on gives plain path tracing's bits again, 0 subpaths per sample is the
// default 1/16, and bad arguments are one-line errors that change nothing.
TEST(RuntimeCApi, LightPathsSwitchBetweenRefreshes) {
  if (!has_device()) GTEST_SKIP() << "no Vulkan device";
  const auto page_after_two_samples = [](const auto& configure) {
    ExitanceRuntime* rt = nullptr;
    EXPECT_EQ(exitance_runtime_open(bundle().c_str(), nullptr, &rt), EXITANCE_RUNTIME_OK);
    configure(rt);
    ExitanceRefreshReport report{};
    EXPECT_EQ(exitance_runtime_refresh(rt, 0, 2, &report), EXITANCE_RUNTIME_OK);
    EXPECT_EQ(report.samples_per_texel, 2u);
    ExitanceRuntimePageInfo page{};
    EXPECT_EQ(exitance_runtime_page_info(rt, 0, &page), EXITANCE_RUNTIME_OK);
    std::vector<float> rgb(size_t(page.width) * page.height * 3);
    EXPECT_EQ(exitance_runtime_read_page(rt, 0, rgb.data(), page.width, page.height), EXITANCE_RUNTIME_OK);
    exitance_runtime_release(rt);
    return rgb;
  };
  const std::vector<float> plain = page_after_two_samples([](ExitanceRuntime*) {});
  const std::vector<float> connected = page_after_two_samples([](ExitanceRuntime* rt) {
    EXPECT_EQ(exitance_runtime_set_light_paths(rt, 1, 0), EXITANCE_RUNTIME_OK);
  });
  EXPECT_NE(plain, connected);
  for (float v : connected) ASSERT_TRUE(std::isfinite(v) && v >= 0);
  EXPECT_EQ(page_after_two_samples([](ExitanceRuntime* rt) {
              EXPECT_EQ(exitance_runtime_set_light_paths(rt, 1, 0.5), EXITANCE_RUNTIME_OK);
              EXPECT_EQ(exitance_runtime_set_light_paths(rt, 0, 0), EXITANCE_RUNTIME_OK);
            }),
            plain);
  EXPECT_EQ(page_after_two_samples([](ExitanceRuntime* rt) {
              EXPECT_EQ(exitance_runtime_set_light_paths(rt, 2, 0), EXITANCE_RUNTIME_INVALID_ARGUMENT);
              EXPECT_EQ(std::string(exitance_runtime_last_error_message()),
                        "exitance_runtime_set_light_paths: on must be 0 or 1");
              EXPECT_EQ(exitance_runtime_set_light_paths(rt, 1, std::numeric_limits<double>::quiet_NaN()),
                        EXITANCE_RUNTIME_INVALID_ARGUMENT);
              EXPECT_EQ(exitance_runtime_set_light_paths(rt, 1, 65), EXITANCE_RUNTIME_INVALID_ARGUMENT);
              EXPECT_EQ(exitance_runtime_set_light_paths(rt, 1, -1), EXITANCE_RUNTIME_INVALID_ARGUMENT);
              EXPECT_EQ(exitance_runtime_set_light_paths(rt, 1, 1.0 / 16), EXITANCE_RUNTIME_OK);
            }),
            connected);
  EXPECT_EQ(exitance_runtime_set_light_paths(nullptr, 1, 0), EXITANCE_RUNTIME_INVALID_ARGUMENT);
}

// A bundle baked with --directional sh1: read_page_channel returns the refreshed sh1 layers exactly as
// write_bundle writes them, and "R" exactly as read_page; an unknown channel is one error naming it
// and changes nothing.
TEST(RuntimeCApi, ReadPageChannelReturnsTheRefreshedDirectionalLayers) {
  if (!has_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path dir = bundle().parent_path();
  const std::string command = std::string(EXITANCE_BAKE) + " " + EXITANCE_SAMPLE_DIR + "/cornell_room.gltf -o " +
                              (dir / "sh1.bake").string() +
                              " --backend cpu --spp 1 --texel-density 4 --probes none --voxel-resolution none"
                              " --directional sh1 2>/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  ExitanceRuntime* rt = nullptr;
  ASSERT_EQ(exitance_runtime_open((dir / "sh1.bake").c_str(), nullptr, &rt), EXITANCE_RUNTIME_OK)
      << exitance_runtime_last_error_message();
  ExitanceRefreshReport report{};
  ASSERT_EQ(exitance_runtime_refresh(rt, 0, 4, &report), EXITANCE_RUNTIME_OK);
  ExitanceRuntimePageInfo page{};
  ASSERT_EQ(exitance_runtime_page_info(rt, 0, &page), EXITANCE_RUNTIME_OK);
  const size_t texels = size_t(page.width) * page.height;
  std::vector<float> rgb(texels * 3), red(texels), sh1(texels);
  ASSERT_EQ(exitance_runtime_read_page(rt, 0, rgb.data(), page.width, page.height), EXITANCE_RUNTIME_OK);
  ASSERT_EQ(exitance_runtime_read_page_channel(rt, 0, "R", red.data(), page.width, page.height), EXITANCE_RUNTIME_OK);
  for (size_t i = 0; i < texels; ++i) ASSERT_EQ(red[i], rgb[i * 3]) << i;

  EXPECT_EQ(exitance_runtime_read_page_channel(rt, 0, "sh1.w.R", sh1.data(), page.width, page.height),
            EXITANCE_RUNTIME_INVALID_ARGUMENT);
  const std::string message = exitance_runtime_last_error_message();
  EXPECT_NE(message.find("exitance_runtime_read_page_channel: channel \"sh1.w.R\" is not in page 0"), std::string::npos)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);

  ASSERT_EQ(exitance_runtime_read_page_channel(rt, 0, "sh1.y.G", sh1.data(), page.width, page.height), EXITANCE_RUNTIME_OK);
  const fs::path written = dir / "sh1-refreshed.bake";
  ASSERT_EQ(exitance_runtime_write_bundle(rt, written.c_str()), EXITANCE_RUNTIME_OK) << exitance_runtime_last_error_message();
  // This bundle has neither probes nor svo.bin: their device buffers are one-line refusals.
  ExitanceRuntimeProbeBuffer probes{};
  EXPECT_EQ(exitance_runtime_publish_probes(rt, &probes, nullptr), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  const std::string no_probes = exitance_runtime_last_error_message();
  EXPECT_NE(no_probes.find("exitance_runtime_publish_probes: the session refreshes no light probes"), std::string::npos) << no_probes;
  EXPECT_EQ(probes.buffer, VkBuffer(VK_NULL_HANDLE));
  ExitanceRuntimeVoxelBuffer voxels{};
  EXPECT_EQ(exitance_runtime_publish_voxel_exitance(rt, &voxels, nullptr), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  const std::string no_svo = exitance_runtime_last_error_message();
  EXPECT_NE(no_svo.find("exitance_runtime_publish_voxel_exitance: the bundle has no svo.bin"), std::string::npos) << no_svo;
  EXPECT_EQ(no_svo.find('\n'), std::string::npos);
  exitance_runtime_release(rt);
  const exitance::formats::LightmapImage image = exitance::formats::read_lightmap_exr((written / "lightmap-0.exr").string());
  ASSERT_TRUE(image.channels.count("sh1.y.G"));
  EXPECT_TRUE(image.channels.at("sh1.y.G") == sh1) << "read_page_channel differs from the written layer";
  size_t nonzero = 0;
  for (float v : sh1) {
    ASSERT_TRUE(std::isfinite(v));
    nonzero += v != 0;
  }
  EXPECT_GT(nonzero, texels / 4);  // the room's light arrives from above: L1's y component is not 0
}

}  // namespace
