// The runtime's refreshed light probes (docs/runtime.md "Probes", vulkan/probe_refresh.h) on
// lavapipe with validation: refreshed in the frames of RefreshSession::refresh, a stratified set of
// a batch of probes per call, they add up to the whole-run probe bake with the same seed (the same
// paths, summed in the same order); an edit keeps what probes showed until their refreshed estimate
// of the edited scene has its set, which then equals a whole-run bake of the edited scene. The C API
// reads them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/formats/half_float.h"
#include "exitance/formats/probe_grid.h"
#include "exitance/formats/svo_file.h"
#include "exitance/runtime/refresh/refreshed_bundle.h"

#include <nlohmann/json.hpp>
#include "exitance/runtime/bundle/probe_results.h"
#include "exitance/runtime/exitance_runtime.h"
#include "exitance/runtime/exitance_runtime_vulkan.h"
#include "exitance/runtime/refresh/refresh_session.h"
#include "exitance/runtime/world_box.h"
#include "support/fresh_temp_dir.h"
#include "support/vulkan_device_available.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;
using testing::has_vulkan_device;

constexpr uint32_t kProbeSpp = 64;  // one stratified set (kProbeStratifiedSetSize is 256)

// The Cornell room with a coarse probe grid, its probes baked at kProbeSpp on the CPU.
fs::path probe_bundle() {
  static const fs::path bundle = [] {
    const fs::path dir = testing::fresh_temp_dir("probe-refresh");
    BakeOptions options;
    options.input = (fs::path(EXITANCE_SAMPLE_DIR) / "cornell_room.gltf").string();
    options.output = (dir / "cornell.bake").string();
    options.backend.name = "cpu";
    options.atlas.texel_density = 2.0f;
    options.lighting.spp = 4;
    options.lighting.seed = 3;
    options.probe_spacing = 1.0f;
    options.probe_spp = kProbeSpp;
    options.voxel_resolution = 16;
    Diagnostics diagnostics;
    run_bake(options, diagnostics);
    return fs::path(options.output);
  }();
  return bundle;
}

std::vector<std::string>& validation_messages() {
  static std::vector<std::string> messages;
  return messages;
}

std::unique_ptr<RefreshSession> open_session(uint64_t seed) {
  RefreshSessionOptions options;
  options.seed = seed;
  options.device.validation = true;
  options.device.on_validation_message = [](const std::string& m) { validation_messages().push_back(m); };
  return RefreshSession::open(probe_bundle().string(), options);
}

// Frames of a generous budget until every probe has kProbeSpp refreshed samples.
void refresh_probes(RefreshSession& session) {
  for (int frame = 0; frame < 200 && session.probe_samples() < kProbeSpp; ++frame) {
    RefreshBudget budget;
    budget.milliseconds = 2000;
    budget.max_samples_per_texel = 1;  // the lightmap's part stays small
    const RefreshReport report = session.refresh(budget);
    EXPECT_GT(report.probes_refreshed, 0u) << "frame " << frame;
  }
  ASSERT_EQ(session.probe_samples(), kProbeSpp);
}

// The grid a whole-run probe bake of the session's scene gives, as probes.bin stores it.
formats::ProbeGrid whole_run_probes(RefreshSession& session) {
  formats::ProbeGrid grid = session.persisted().probes;
  std::vector<size_t> traced;
  for (size_t i = 0; i < grid.probes.size(); ++i)
    if (formats::probe_is_usable(grid.probes[i])) traced.push_back(i);
  store_probe_radiance(grid, traced, session.probe_estimate(kProbeSpp), 0.0f);
  return grid;
}

void expect_same_probes(const formats::ProbeGrid& a, const formats::ProbeGrid& b, const char* what) {
  ASSERT_EQ(a.probes.size(), b.probes.size()) << what;
  size_t lit = 0;
  for (size_t i = 0; i < a.probes.size(); ++i)
    for (size_t k = 0; k < 27; ++k) {
      EXPECT_NEAR(a.probes[i].sh[k], b.probes[i].sh[k], 1e-6f * std::fabs(b.probes[i].sh[k]) + 1e-9f)
          << what << ": probe " << i << " coefficient " << k;
      lit += b.probes[i].sh[k] != 0;
    }
  EXPECT_GT(lit, a.probes.size()) << what;
}

TEST(ProbeRefresh, FramesAddUpToTheWholeRunBake) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  auto session = open_session(21);
  const formats::ProbeGrid at_open = session->published_probes();
  ASSERT_FALSE(at_open.probes.empty());
  refresh_probes(*session);
  expect_same_probes(session->published_probes(), whole_run_probes(*session), "refreshed at open");
  // At open the refreshed probes replaced the bundle's only at as many samples as it has: not before.
  for (const std::string& m : validation_messages()) ADD_FAILURE() << "validation: " << m;
  validation_messages().clear();
}

// The tall box's bounds as the session's scene has them now.
WorldBox tall_box(RefreshSession& session) {
  const Scene& scene = session.persisted().scene;
  WorldBox box;
  for (const Instance& instance : scene.instances)
    if (instance.name == "TallBox")
      for (uint32_t t = instance.first_triangle; t < instance.first_triangle + instance.triangle_count; ++t)
        for (int v = 0; v < 3; ++v) box.grow(scene.positions[size_t(t) * 3 + size_t(v)]);
  EXPECT_FALSE(box.empty());
  return box;
}

// The tall box moved (a restart, as every edit that does not only scale lights).
constexpr const char* kBoxMoved = R"({"edits": [{"node": "TallBox", "translation": [-0.55, 0.0, 0.2]}]})";

TEST(ProbeRefresh, AnEditShowsThePreviousProbesUntilTheirSetIsDone) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  auto session = open_session(22);
  refresh_probes(*session);
  const formats::ProbeGrid before = session->published_probes();
  const WorldBox box_before = tall_box(*session);
  session->apply_edits(parse_scene_edits(kBoxMoved, "box.json"));
  const WorldBox box_after = tall_box(*session);
  EXPECT_EQ(session->probe_samples(), 0u);
  expect_same_probes(session->published_probes(), before, "right after the edit");
  // A frame that refreshes a first batch of probes: those nearest the moved box (its bounds before
  // and after), and they alone may show the edited scene.
  RefreshBudget small;
  small.milliseconds = 1e-3;
  small.max_samples_per_texel = 1;
  session->refresh(small);
  {
    const ProbeEstimate first = session->integrator().probe_refresh_estimate();
    const std::vector<formats::ProbeRecord>& grid = session->persisted().probes.probes;
    float farthest_refreshed = 0, nearest_other = INFINITY;
    size_t refreshed = 0, k = 0;
    for (const formats::ProbeRecord& r : grid) {
      if (!formats::probe_is_usable(r)) continue;
      const Vec3 p{r.position[0], r.position[1], r.position[2]};
      const float d = std::min(box_before.distance_squared(p), box_after.distance_squared(p));
      if (first.samples[k++] > 0) farthest_refreshed = std::max(farthest_refreshed, d), ++refreshed;
      else nearest_other = std::min(nearest_other, d);
    }
    ASSERT_GT(refreshed, 0u);
    ASSERT_LT(refreshed, first.samples.size()) << "the test needs a partial batch";
    EXPECT_LE(farthest_refreshed, nearest_other);
  }
  refresh_probes(*session);
  // Each probe shows its refreshed estimate of the edited scene (= the whole-run bake's) or, where
  // that is not the better by the publishing rule, what it showed before the edit.
  const formats::ProbeGrid after = session->published_probes();
  const formats::ProbeGrid whole_run = whole_run_probes(*session);
  size_t refreshed_shown = 0;
  for (size_t i = 0; i < after.probes.size(); ++i) {
    const bool as_before = after.probes[i].sh == before.probes[i].sh;
    refreshed_shown += !as_before;
    if (as_before) continue;
    for (size_t k = 0; k < 27; ++k)
      EXPECT_NEAR(after.probes[i].sh[k], whole_run.probes[i].sh[k], 1e-6f * std::fabs(whole_run.probes[i].sh[k]) + 1e-9f)
          << "probe " << i << " coefficient " << k;
  }
  EXPECT_GT(refreshed_shown, 0u);

  // The C API reads the same grid; a wrong count is one line and changes nothing.
  ExitanceRuntime* runtime = nullptr;
  ASSERT_EQ(exitance_runtime_open(probe_bundle().string().c_str(), nullptr, &runtime), EXITANCE_RUNTIME_OK);
  uint32_t count = 0;
  ASSERT_EQ(exitance_runtime_probe_count(runtime, &count), EXITANCE_RUNTIME_OK);
  EXPECT_EQ(count, uint32_t(after.probes.size()));
  std::vector<float> sh(size_t(count) * 27, -1.0f);
  EXPECT_EQ(exitance_runtime_read_probes(runtime, sh.data(), count + 1, nullptr), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_NE(std::string(exitance_runtime_last_error_message()).find("probe_count"), std::string::npos) << exitance_runtime_last_error_message();
  EXPECT_EQ(sh[0], -1.0f);
  uint32_t samples = 99;
  ASSERT_EQ(exitance_runtime_read_probes(runtime, sh.data(), count, &samples), EXITANCE_RUNTIME_OK);
  EXPECT_EQ(samples, 0u);  // nothing refreshed yet: the bundle's probes
  size_t nonzero = 0;
  for (float v : sh) nonzero += v != 0;
  EXPECT_GT(nonzero, size_t(count));
  // The probes' share of a frame: outside [0, 1] refused in one line; 0 refreshes none.
  EXPECT_EQ(exitance_runtime_set_probe_budget_share(runtime, 1.5), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_NE(std::string(exitance_runtime_last_error_message()).find("not in [0, 1]"), std::string::npos);
  EXPECT_EQ(exitance_runtime_set_probe_budget_share(runtime, NAN), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  ASSERT_EQ(exitance_runtime_set_probe_budget_share(runtime, 0.0), EXITANCE_RUNTIME_OK);
  ExitanceRefreshReport frame;
  ASSERT_EQ(exitance_runtime_refresh(runtime, 500.0, 1, &frame), EXITANCE_RUNTIME_OK);
  ASSERT_EQ(exitance_runtime_read_probes(runtime, sh.data(), count, &samples), EXITANCE_RUNTIME_OK);
  EXPECT_EQ(samples, 0u);
  ASSERT_EQ(exitance_runtime_set_probe_budget_share(runtime, 1.0), EXITANCE_RUNTIME_OK);
  const std::vector<float> baked = sh;
  ASSERT_EQ(exitance_runtime_refresh(runtime, 500.0, 1, &frame), EXITANCE_RUNTIME_OK);
  ASSERT_EQ(exitance_runtime_read_probes(runtime, sh.data(), count, &samples), EXITANCE_RUNTIME_OK);
  size_t replaced = 0;  // probes whose set is done show the refreshed estimate (the bundle's was baked on the CPU)
  for (size_t i = 0; i < count; ++i) replaced += std::memcmp(&sh[i * 27], &baked[i * 27], 27 * sizeof(float)) != 0;
  EXPECT_GT(replaced, 0u);
  exitance_runtime_release(runtime);
  for (const std::string& m : validation_messages()) ADD_FAILURE() << "validation: " << m;
  validation_messages().clear();
}

// The voxel exitance of what texels show, read without writing a bundle: what write_refreshed_bundle
// writes into svo.bin, before and after an edit.
TEST(ProbeRefresh, VoxelExitanceIsReadableBetweenBundles) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  auto session = open_session(23);
  session->apply_edits(parse_scene_edits(R"({"edits": [{"material": "CeilingLight", "emissiveFactor": [0.6, 0.85, 1.0]}]})", "bluer.json"));
  RefreshBudget budget;
  budget.max_samples_per_texel = 8;
  session->refresh(budget);
  const std::optional<formats::SparseVoxelOctree> shown = session->published_voxel_exitance();
  ASSERT_TRUE(shown.has_value());
  const fs::path out = probe_bundle().parent_path() / "voxels.bake";
  write_refreshed_bundle(*session, out.string(), nlohmann::json::object());
  const formats::SparseVoxelOctree written = formats::read_svo_file((out / "svo.bin").string());
  ASSERT_EQ(shown->nodes.size(), written.nodes.size());
  EXPECT_EQ(shown->exitance_scale, written.exitance_scale);
  size_t lit = 0;
  for (size_t i = 0; i < written.nodes.size(); ++i)
    for (size_t k = 0; k < 6; ++k) {
      EXPECT_EQ(shown->nodes[i].exitance[k], written.nodes[i].exitance[k]) << "node " << i << " side " << k;
      lit += written.nodes[i].exitance[k] != 0;
    }
  EXPECT_GT(lit, 0u);

  // The C API: the same values as the svo.bin its write_bundle writes (half floats times the scale);
  // a wrong count is one line and writes nothing.
  ExitanceRuntime* runtime = nullptr;
  ASSERT_EQ(exitance_runtime_open(probe_bundle().string().c_str(), nullptr, &runtime), EXITANCE_RUNTIME_OK);
  ASSERT_EQ(exitance_runtime_apply_edits(runtime, R"({"edits": [{"material": "CeilingLight", "emissiveFactor": [0.6, 0.85, 1.0]}]})"),
            EXITANCE_RUNTIME_OK);
  ExitanceRefreshReport frame;
  ASSERT_EQ(exitance_runtime_refresh(runtime, 0, 4, &frame), EXITANCE_RUNTIME_OK);
  uint32_t count = 0;
  ASSERT_EQ(exitance_runtime_voxel_count(runtime, &count), EXITANCE_RUNTIME_OK);
  ASSERT_EQ(count, uint32_t(written.nodes.size()));
  std::vector<float> exitance(size_t(count) * 6, -1.0f);
  EXPECT_EQ(exitance_runtime_read_voxel_exitance(runtime, exitance.data(), count - 1), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  const std::string message = exitance_runtime_last_error_message();
  EXPECT_NE(message.find("exitance_runtime_read_voxel_exitance: count"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
  EXPECT_EQ(exitance[0], -1.0f);
  EXPECT_EQ(exitance_runtime_read_voxel_exitance(runtime, nullptr, count), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  ASSERT_EQ(exitance_runtime_read_voxel_exitance(runtime, exitance.data(), count), EXITANCE_RUNTIME_OK);
  const fs::path from_c = probe_bundle().parent_path() / "voxels-c.bake";
  ASSERT_EQ(exitance_runtime_write_bundle(runtime, from_c.string().c_str()), EXITANCE_RUNTIME_OK) << exitance_runtime_last_error_message();
  const formats::SparseVoxelOctree c_written = formats::read_svo_file((from_c / "svo.bin").string());
  ASSERT_EQ(c_written.nodes.size(), size_t(count));
  size_t differing = 0, nonzero = 0;
  for (size_t i = 0; i < c_written.nodes.size(); ++i)
    for (size_t k = 0; k < 6; ++k) {
      const float value = formats::half_to_float(c_written.nodes[i].exitance[k]) * c_written.exitance_scale;
      differing += exitance[i * 6 + k] != value;
      nonzero += value != 0;
    }
  EXPECT_EQ(differing, 0u);
  EXPECT_GT(nonzero, 0u);
  exitance_runtime_release(runtime);
}

// An edit while only some probes show their refreshed estimate keeps exactly what each showed.
TEST(ProbeRefresh, AnEditKeepsWhatEachProbeShowed) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  auto session = open_session(24);
  const formats::ProbeGrid baked = session->published_probes();
  RefreshBudget budget;
  budget.milliseconds = 2000;
  budget.max_samples_per_texel = 1;
  const RefreshReport frame = session->refresh(budget);  // the first batch: 16 probes, unmeasured
  ASSERT_GT(frame.probes_refreshed, 0u);
  ASSERT_EQ(session->probe_samples(), 0u) << "every probe refreshed: the test needs a partial batch";
  const formats::ProbeGrid shown = session->published_probes();
  size_t replaced = 0;
  for (size_t i = 0; i < shown.probes.size(); ++i) replaced += shown.probes[i].sh != baked.probes[i].sh;
  EXPECT_EQ(replaced, size_t(frame.probes_refreshed));
  session->apply_edits(parse_scene_edits(kBoxMoved, "box.json"));
  const formats::ProbeGrid kept = session->published_probes();
  for (size_t i = 0; i < kept.probes.size(); ++i) EXPECT_EQ(kept.probes[i].sh, shown.probes[i].sh) << "probe " << i;
}

// After a local edit the probes near it are refreshed to their target before the others get a sample
// (probes that take two stratified sets: the publishing rule prefers a refreshed estimate with as
// many samples as the value it kept, so the near probes need both sets first). The building at a
// coarse density, one room's point light moved.
// The building at a coarse density with a probe grid of probes of two stratified sets each.
fs::path building_probe_bundle() {
  static const fs::path bundle = [] {
    BakeOptions options;
    options.input = (fs::path(EXITANCE_SAMPLE_DIR) / "building.gltf").string();
    options.output = (probe_bundle().parent_path() / "building-probes.bake").string();
    options.backend.name = "cpu";
    options.atlas.texel_density = 0.5f;
    options.lighting.spp = 1;
    options.probe_spacing = 4.0f;
    options.probe_spp = 2 * kProbeStratifiedSetSize;
    options.voxel_resolution = 0;
    Diagnostics diagnostics;
    run_bake(options, diagnostics);
    return fs::path(options.output);
  }();
  return bundle;
}

// Frames until every probe has `target` refreshed samples (each frame one sample of the lightmap).
void refresh_probes_to(RefreshSession& session, uint32_t target) {
  RefreshBudget frame;
  frame.milliseconds = 5000;
  frame.max_samples_per_texel = 1;
  for (int k = 0; k < 400 && session.probe_samples() < target; ++k) session.refresh(frame);
  ASSERT_EQ(session.probe_samples(), target);
}

Vec3 light_position(const RefreshSession& session, const char* name) {
  for (const PunctualLight& light : session.persisted().scene.lights)
    if (light.name == name) return light.position;
  ADD_FAILURE() << "no light " << name;
  return Vec3{0, 0, 0};
}

constexpr const char* kRoomLightMoved = R"({"edits": [{"node": "Room_0_0_2_Point", "translation": [4.2, 2.2, 12.0]}]})";

TEST(ProbeRefresh, TheProbesNearALocalEditReachTheirTargetFirst) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  RefreshSessionOptions options;
  options.seed = 28;
  auto session = RefreshSession::open(building_probe_bundle().string(), options);
  const uint32_t target = 2 * kProbeStratifiedSetSize;
  refresh_probes_to(*session, target);
  const Vec3 before = light_position(*session, "Room_0_0_2_Point");
  session->apply_edits(parse_scene_edits(kRoomLightMoved, "move.json"));
  const Vec3 after = light_position(*session, "Room_0_0_2_Point");
  std::vector<float> distance;
  for (const formats::ProbeRecord& r : session->persisted().probes.probes)
    if (formats::probe_is_usable(r)) {
      const Vec3 p{r.position[0], r.position[1], r.position[2]};
      distance.push_back(std::min(dot(p - before, p - before), dot(p - after, p - after)));
    }
  const size_t nearest = size_t(std::min_element(distance.begin(), distance.end()) - distance.begin());
  const size_t farthest = size_t(std::max_element(distance.begin(), distance.end()) - distance.begin());
  RefreshBudget small;
  small.milliseconds = 1e-3;  // one batch of probes a call
  small.max_samples_per_texel = 1;
  ProbeEstimate now;
  for (int k = 0; k < 400; ++k) {
    session->refresh(small);
    now = session->integrator().probe_refresh_estimate();
    if (now.samples[nearest] >= target) break;
  }
  ASSERT_EQ(now.samples[nearest], target);
  // Round robin over all probes would have given the farthest its first set before the nearest its second.
  EXPECT_EQ(now.samples[farthest], 0u) << "farthest at " << std::sqrt(distance[farthest]) << " m of " << distance.size() << " probes";
}

// The probes as an engine reads them on the device (publish_probe_buffer, exitance_runtime_publish_probes):
// the values published_probes() gives, bit for bit, at open, part way through a set, after a
// restart (the box moved: some probes refreshed, others keeping what they showed), once refreshed,
// and after an edit that scales a light.
void expect_buffer_is_published(RefreshSession& session, const char* when) {
  session.publish_probe_buffer();
  const std::vector<float> buffer = session.read_probe_buffer();
  const formats::ProbeGrid grid = session.published_probes();
  ASSERT_EQ(buffer.size(), grid.probes.size() * 27) << when;
  size_t differing = 0;
  for (size_t i = 0; i < grid.probes.size(); ++i)
    differing += std::memcmp(&buffer[i * 27], grid.probes[i].sh.data(), 27 * sizeof(float)) != 0;
  EXPECT_EQ(differing, 0u) << when;
}

// One refresh call whose budget holds one batch of probes.
void refresh_one_probe_batch(RefreshSession& session) {
  RefreshBudget small;
  small.milliseconds = 1e-3;
  small.max_samples_per_texel = 1;
  session.refresh(small);
}

TEST(ProbeRefresh, TheDeviceBufferHoldsWhatProbesShow) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  auto session = open_session(26);
  expect_buffer_is_published(*session, "at open");
  refresh_one_probe_batch(*session);
  expect_buffer_is_published(*session, "one batch refreshed");
  refresh_probes(*session);
  expect_buffer_is_published(*session, "refreshed");
  session->apply_edits(parse_scene_edits(kBoxMoved, "box.json"));
  expect_buffer_is_published(*session, "after the box moved");
  refresh_one_probe_batch(*session);
  expect_buffer_is_published(*session, "after the box moved, one batch");
  refresh_probes(*session);
  expect_buffer_is_published(*session, "after the box moved, refreshed");
  session->apply_edits(parse_scene_edits(R"({"edits": [{"material": "CeilingLight", "emissiveFactor": [0.6, 0.85, 1.0]}]})", "bluer.json"));
  expect_buffer_is_published(*session, "after a scaling edit");
  const DeviceProbeBuffer first = session->publish_probe_buffer();
  const DeviceProbeBuffer again = session->publish_probe_buffer();
  EXPECT_EQ(first.buffer, again.buffer);
  EXPECT_EQ(first.size, VkDeviceSize(session->persisted().probes.probes.size()) * 108);
  if (first.ready) EXPECT_EQ(again.ready_value, first.ready_value + 1);

  // The C API hands the same over; NULL is one line and changes nothing.
  ExitanceRuntime* runtime = nullptr;
  ASSERT_EQ(exitance_runtime_open(probe_bundle().string().c_str(), nullptr, &runtime), EXITANCE_RUNTIME_OK);
  ExitanceRuntimeProbeBuffer probes{};
  ExitanceRuntimeImagesReady ready{};
  EXPECT_EQ(exitance_runtime_publish_probes(runtime, nullptr, &ready), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_NE(std::string(exitance_runtime_last_error_message()).find("exitance_runtime_publish_probes"), std::string::npos)
      << exitance_runtime_last_error_message();
  ASSERT_EQ(exitance_runtime_publish_probes(runtime, &probes, &ready), EXITANCE_RUNTIME_OK);
  uint32_t count = 0;
  ASSERT_EQ(exitance_runtime_probe_count(runtime, &count), EXITANCE_RUNTIME_OK);
  EXPECT_NE(probes.buffer, VkBuffer(VK_NULL_HANDLE));
  EXPECT_EQ(probes.probe_count, count);
  EXPECT_EQ(probes.size, VkDeviceSize(count) * 108);
  exitance_runtime_release(runtime);
  for (const std::string& m : validation_messages()) ADD_FAILURE() << "validation: " << m;
  validation_messages().clear();
}

// The voxel exitance computed on the device (publish_voxel_exitance, exitance_runtime_publish_voxel_exitance)
// against the host's (published_voxel_exitance, what svo.bin gets): equal up to svo.bin's half-float
// encoding (11 significant bits: 2^-11 relative, below 2^-24 of the scale absolute) and the host's
// running means in float (a few float roundings per level); lit and filled sides the same. At open,
// after refreshing, after the box moved (texels deposit elsewhere) and after a scaling edit.
void expect_device_voxels_are_shown(RefreshSession& session, const char* when) {
  session.publish_voxel_exitance();
  const std::vector<float> device = session.read_voxel_exitance();
  const std::optional<formats::SparseVoxelOctree> host = session.published_voxel_exitance();
  ASSERT_TRUE(host.has_value());
  ASSERT_EQ(device.size(), host->nodes.size() * 6) << when;
  size_t lit = 0, off = 0;
  for (size_t i = 0; i < host->nodes.size(); ++i)
    for (size_t k = 0; k < 6; ++k) {
      const float h = formats::half_to_float(host->nodes[i].exitance[k]) * host->exitance_scale;
      const float d = device[i * 6 + k];
      off += !(std::fabs(d - h) <= 1e-3f * std::fabs(h) + 1e-7f * host->exitance_scale);
      lit += h != 0;
    }
  EXPECT_EQ(off, 0u) << when;
  EXPECT_GT(lit, host->nodes.size()) << when;
}

TEST(ProbeRefresh, TheDeviceVoxelExitanceIsWhatTexelsShow) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  auto session = open_session(27);
  RefreshBudget budget;
  budget.max_samples_per_texel = 4;
  session->refresh(budget);
  expect_device_voxels_are_shown(*session, "refreshed");
  session->apply_edits(parse_scene_edits(kBoxMoved, "box.json"));
  budget.max_samples_per_texel = 8;
  session->refresh(budget);
  expect_device_voxels_are_shown(*session, "after the box moved");
  session->apply_edits(parse_scene_edits(R"({"edits": [{"material": "CeilingLight", "emissiveFactor": [0.6, 0.85, 1.0]}]})", "bluer.json"));
  expect_device_voxels_are_shown(*session, "after a scaling edit");
  const DeviceVoxelExitance first = session->publish_voxel_exitance();
  EXPECT_EQ(first.size, VkDeviceSize(session->svo()->nodes.size()) * 24);

  ExitanceRuntime* runtime = nullptr;
  ASSERT_EQ(exitance_runtime_open(probe_bundle().string().c_str(), nullptr, &runtime), EXITANCE_RUNTIME_OK);
  ExitanceRuntimeVoxelBuffer voxels{};
  EXPECT_EQ(exitance_runtime_publish_voxel_exitance(runtime, nullptr, nullptr), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  ASSERT_EQ(exitance_runtime_publish_voxel_exitance(runtime, &voxels, nullptr), EXITANCE_RUNTIME_OK);
  uint32_t count = 0;
  ASSERT_EQ(exitance_runtime_voxel_count(runtime, &count), EXITANCE_RUNTIME_OK);
  EXPECT_EQ(voxels.node_count, count);
  EXPECT_NE(voxels.buffer, VkBuffer(VK_NULL_HANDLE));
  exitance_runtime_release(runtime);
  for (const std::string& m : validation_messages()) ADD_FAILURE() << "validation: " << m;
  validation_messages().clear();
}

// Light layers (docs/runtime.md "Probes"): each probe's sums split by light add up to its totals,
// and an edit that only scales a light's emission scales them on the device with 0 rays, keeping
// every sample: the probes then show what a whole-run bake of the edited scene gives (the room has
// one emitting material, so scaling it leaves the light choice, and hence every path, as it was).
TEST(ProbeRefresh, AnEditThatScalesALightScalesTheProbesAtOnce) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  auto session = open_session(25);
  refresh_probes(*session);
  const int layers = session->integrator().probe_refresh_light_layers();
  ASSERT_GT(layers, 1);
  const ProbeEstimate before = session->integrator().probe_refresh_estimate(true);
  ASSERT_EQ(before.light_layers, layers);
  ASSERT_EQ(before.light_sh_sum.size(), size_t(layers) * before.sh_sum.size());
  ASSERT_EQ(before.l0_square_sum.size(), before.sh_sum.size());
  size_t lit = 0;
  for (size_t p = 0; p < before.sh_sum.size(); ++p)
    for (size_t k = 0; k < 27; ++k) {
      double sum = 0, magnitude = 0;
      for (int l = 0; l < layers; ++l) {
        sum += before.light_sh_sum[size_t(l) * before.sh_sum.size() + p][k];
        magnitude += std::fabs(before.light_sh_sum[size_t(l) * before.sh_sum.size() + p][k]);
      }
      // The same float radiance summed per layer: equal up to double rounding.
      EXPECT_NEAR(sum, before.sh_sum[p][k], 1e-12 * (magnitude + std::fabs(before.sh_sum[p][k])) + 1e-300)
          << "probe " << p << " coefficient " << k;
      lit += before.sh_sum[p][k] != 0;
    }
  EXPECT_GT(lit, before.sh_sum.size());
  const formats::ProbeGrid shown_before = session->published_probes();

  session->apply_edits(parse_scene_edits(R"({"edits": [{"material": "CeilingLight", "emissiveFactor": [0.6, 0.85, 1.0]}]})", "bluer.json"));
  EXPECT_TRUE(session->last_edit_timings().scaled_light_layers);
  EXPECT_EQ(session->probe_samples(), kProbeSpp);  // no sample dropped
  const formats::ProbeGrid after = session->published_probes();
  const formats::ProbeGrid whole_run = whole_run_probes(*session);
  size_t changed = 0;
  for (size_t i = 0; i < after.probes.size(); ++i) {
    // Each sample's float radiance was scaled after the sum rather than before it: a relative
    // difference of a few float roundings of the probe's own L0 term of that channel.
    for (size_t k = 0; k < 27; ++k) {
      const float scale = std::fabs(whole_run.probes[i].sh[k % 3]);
      EXPECT_NEAR(after.probes[i].sh[k], whole_run.probes[i].sh[k], 1e-5f * scale + 1e-9f) << "probe " << i << " coefficient " << k;
    }
    changed += after.probes[i].sh != shown_before.probes[i].sh;
  }
  EXPECT_GT(changed, after.probes.size() / 2);
  for (const std::string& m : validation_messages()) ADD_FAILURE() << "validation: " << m;
  validation_messages().clear();
}

// A point light moved after the probes were refreshed: as the lightmap, the probes estimate the
// light's change from what they showed (the same paths, each vertex adding the moved light's direct
// light as moved minus as it was; docs/runtime.md "Probes"). Probes the light reaches neither before
// nor after get a change of exactly 0 and show their pre-edit value bit for bit; the others show
// base + change, which agrees with a whole-run bake of the edited scene within the noise and is
// closer to it than the pre-edit values. The device buffer holds what the host shows throughout.
TEST(ProbeRefresh, ALightMoveIsEstimatedAsAChangeOfTheProbes) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  RefreshSessionOptions options;
  options.seed = 31;
  options.device.validation = true;
  options.device.on_validation_message = [](const std::string& m) { validation_messages().push_back(m); };
  auto session = RefreshSession::open(building_probe_bundle().string(), options);
  const uint32_t target = 2 * kProbeStratifiedSetSize;
  refresh_probes_to(*session, target);
  RefreshBudget lightmap;  // samples enough for the lightmap's change estimate (2 per texel)
  lightmap.max_samples_per_texel = 4;
  session->refresh(lightmap);
  const formats::ProbeGrid before = session->published_probes();
  const ProbeEstimate refreshed_before = session->integrator().probe_refresh_estimate();
  ASSERT_EQ(refreshed_before.l0_square_sum.size(), refreshed_before.samples.size());

  session->apply_edits(parse_scene_edits(kRoomLightMoved, "move.json"));
  ASSERT_TRUE(session->integrator().probe_refresh_as_change()) << "the lightmap's change estimate did not start";
  // No change sample yet: every probe shows what it showed.
  const formats::ProbeGrid at_edit = session->published_probes();
  for (size_t i = 0; i < at_edit.probes.size(); ++i) EXPECT_EQ(at_edit.probes[i].sh, before.probes[i].sh) << "probe " << i;
  expect_buffer_is_published(*session, "at the light move");
  refresh_one_probe_batch(*session);
  expect_buffer_is_published(*session, "one batch after the light move");
  refresh_probes_to(*session, target);
  expect_buffer_is_published(*session, "refreshed after the light move");

  const formats::ProbeGrid after = session->published_probes();
  const ProbeEstimate change = session->integrator().probe_refresh_estimate();
  const ProbeEstimate fresh = session->probe_estimate(target);  // a whole run of the edited scene
  std::vector<size_t> grid_index;
  for (size_t i = 0; i < after.probes.size(); ++i)
    if (formats::probe_is_usable(after.probes[i])) grid_index.push_back(i);
  ASSERT_EQ(grid_index.size(), change.samples.size());
  ASSERT_EQ(fresh.samples.size(), change.samples.size());
  size_t unreached = 0, shown_changed = 0;
  double shown_minus_fresh = 0, variance = 0, error_after = 0, error_before = 0;
  for (size_t k = 0; k < grid_index.size(); ++k) {
    const size_t i = grid_index[k];
    bool zero = true;
    for (double v : change.sh_sum[k]) zero = zero && v == 0;
    if (zero) {
      ++unreached;
      EXPECT_EQ(after.probes[i].sh, before.probes[i].sh) << "probe " << i << ": no change, yet its value moved";
      continue;
    }
    if (after.probes[i].sh == before.probes[i].sh) continue;  // a change within its noise: the base shown
    ++shown_changed;
    const ShRgb f = fresh.mean(k);
    for (int c = 0; c < 3; ++c) {
      const double a = after.probes[i].sh[size_t(c)], b = before.probes[i].sh[size_t(c)];
      shown_minus_fresh += a - f[0][c];
      error_after += (a - f[0][c]) * (a - f[0][c]);
      error_before += (b - f[0][c]) * (b - f[0][c]);
    }
    variance += refreshed_before.l0_variance_of_mean(k) + change.l0_variance_of_mean(k) + fresh.l0_variance_of_mean(k);
  }
  EXPECT_GT(unreached, 0u) << "every probe saw the moved light: the test needs probes in other rooms";
  ASSERT_GT(shown_changed, 0u) << "no probe shows a change";
  // The L0 sums over the probes that show a change, against the whole run (independent variances
  // summed: the shared random numbers only correlate them positively).
  EXPECT_LT(std::fabs(shown_minus_fresh), 4.0 * std::sqrt(variance))
      << shown_changed << " probes: base + change minus the whole run " << shown_minus_fresh << ", standard error " << std::sqrt(variance);
  EXPECT_LT(error_after, error_before) << "the refreshed probes are further from the edited scene than before the edit";
  // A restart ends the change estimate: the probes keep what they show and start again.
  session->restart();
  EXPECT_FALSE(session->integrator().probe_refresh_as_change());
  const formats::ProbeGrid after_restart = session->published_probes();
  for (size_t i = 0; i < after.probes.size(); ++i) EXPECT_EQ(after_restart.probes[i].sh, after.probes[i].sh) << "probe " << i;
  expect_buffer_is_published(*session, "after the change estimate ended");
  for (const std::string& m : validation_messages()) ADD_FAILURE() << "validation: " << m;
  validation_messages().clear();
}

}  // namespace
}  // namespace exitance
