// bake's guiding options that contradict the rest of the command line (docs/cli.md, --guiding,
// --emitter-guiding): one line naming the option and the conflict, exit 2, and no bundle written.
// They are refused before any stage runs, so the sample scene costs nothing here.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "support/fresh_temp_dir.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST(BakeGuidingOptions, ContradictionsAreOneLineAndExit2) {
  const fs::path dir = testing::fresh_temp_dir("guiding-options");
  const struct {
    const char* options;
    const char* expected;  // in the one error line
  } cases[] = {
      {"--guiding svo --voxel-resolution none", "--guiding svo builds its fields from the voxel octree"},
      {"--guiding svo --integrator bounces", "--guiding svo guides path tracing"},
      {"--guiding grid --integrator bounces", "--guiding grid guides path tracing"},
      {"--emitter-guiding on --backend vulkan --guiding svo", "--guiding svo beside it runs on the CPU backend only"},
      // Not guiding, but refused the same way (docs/bundle.md "Light layers").
      {"--light-layers --integrator bounces", "--light-layers are kept by path tracing: they need --integrator path"},
      {"--denoise --light-layers", "--denoise filters the indirect light, which --light-layers do not keep apart"},
      {"--denoise --directional sh1", "--denoise filters the indirect light, which --directional sh1 does not keep apart"},
      {"--denoise --denoise-radius 0", "--denoise-radius"},
      // Light subpaths: path-tracing strategies, not combined with path guiding yet.
      {"--light-paths on --integrator bounces", "--light-paths on contradicts --integrator bounces"},
      {"--light-paths on --guiding grid", "--light-paths on contradicts --guiding grid/svo"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.options);
    const fs::path out = dir / "out.bake", err = dir / "stderr.txt";
    EXPECT_EQ(run(std::string(EXITANCE_BAKE) + " " + EXITANCE_SAMPLE_DIR "/cornell_room.gltf --no-cache --spp 1 " +
                  c.options + " -o " + out.string() + " 2>" + err.string() + " >/dev/null"),
              2);
    const std::string message = read_text(err);
    EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
    EXPECT_EQ(message.rfind("bake: error: ", 0), 0u) << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(out));
  }
  fs::remove_all(dir);
}

// A guide the user names guides path tracing, so --integrator auto (the CPU's default would be the
// per-bounce mode) picks path tracing for it, and the report says what was chosen; so does
// --light-paths on, which also turns automatic path guiding off (not combined yet) and keeps
// emitter guiding.
TEST(BakeGuidingOptions, ANamedGuideMakesAutoChoosePathTracing) {
  const fs::path dir = testing::fresh_temp_dir("guiding-choice");
  const struct {
    const char* options;
    const char* integrator;
    const char* guiding;
  } cases[] = {
      {"--guiding svo", "path", "svo"},
      {"--guiding grid", "path", "grid"},
      {"--guiding off", "bounces", "off"},
      {"--light-paths on", "path", "off"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.options);
    const fs::path out = dir / "out.bake", report = dir / "report.json";
    ASSERT_EQ(run(std::string(EXITANCE_BAKE) + " " + EXITANCE_SAMPLE_DIR +
                  "/cornell_room.gltf --no-cache --backend cpu --spp 1 --texel-density 2 --probes none " + c.options +
                  " -o " + out.string() + " --json >" + report.string() + " 2>/dev/null"),
              0);
    const nlohmann::json stats = nlohmann::json::parse(read_text(report));
    EXPECT_EQ(stats.at("lighting").at("integrator"), c.integrator);
    EXPECT_EQ(stats.at("lighting").at("guiding"), c.guiding);
    const bool light_paths = std::string(c.options) == "--light-paths on";
    EXPECT_EQ(stats.at("lighting").at("light_paths"), light_paths);
    if (light_paths) {
      EXPECT_EQ(stats.at("lighting").at("emitter_guiding"), true);
      EXPECT_GT(stats.at("light_paths").at("subpaths").get<uint64_t>(), 0u);
      EXPECT_GT(stats.at("light_paths").at("vertices").get<uint64_t>(), 0u);
    }
    fs::remove_all(out);
  }
  fs::remove_all(dir);
}

// --guiding auto's candidate (issue 35 item 4): light subpaths where the scene has an emitter or a
// point or spot light (the Cornell room's ceiling light) and the bake is long enough for their pilot
// (--spp 1024: four pilots of 256), unless --light-paths off names grid guiding; the report names it.
TEST(BakeGuidingOptions, AutoMeasuresLightPathsUnlessTheyAreOff) {
  const fs::path dir = testing::fresh_temp_dir("guiding-candidate");
  const struct {
    const char* options;
    const char* candidate;
  } cases[] = {
      {"--spp 1024", "light-paths"},
      {"--spp 1024 --light-paths auto --guiding auto", "light-paths"},
      {"--spp 1024 --light-paths off", "grid"},
      {"--spp 512", "grid"},  // too short for the light subpaths' pilot
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.options);
    const fs::path out = dir / "out.bake", report = dir / "report.json";
    ASSERT_EQ(run(std::string(EXITANCE_BAKE) + " " + EXITANCE_SAMPLE_DIR +
                  "/cornell_room.gltf --no-cache --backend cpu --integrator path --texel-density 0.5 --probes none " +
                  c.options + " -o " + out.string() + " --json >" + report.string() + " 2>/dev/null"),
              0);
    const nlohmann::json stats = nlohmann::json::parse(read_text(report));
    EXPECT_EQ(stats.at("lighting").at("guiding"), "auto");
    EXPECT_EQ(stats.at("lighting").at("light_paths"), false);  // not on every sample
    EXPECT_EQ(stats.at("guiding").at("candidate"), c.candidate);
    EXPECT_EQ(stats.at("guiding").at("decided"), true);  // a pilot of 256 (64 for grid guiding)
    EXPECT_EQ(stats.contains("light_paths"), std::string(c.candidate) == "light-paths");  // the pilot's pools
    fs::remove_all(out);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
