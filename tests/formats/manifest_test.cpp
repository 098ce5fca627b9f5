// manifest.json parsing: the DESIGN §4 shape is read field by field; every wrong type, missing
// field, out-of-range index and other version is one FormatError naming the field.
#include <gtest/gtest.h>

#include <limits>
#include <optional>

#include <nlohmann/json.hpp>

#include "byte_patching.h"
#include "exitance/loader/manifest.h"
#include "test_bundle.h"
#include "test_manifest.h"

namespace exitance::loader {
namespace {

using nlohmann::json;
using test::expect_format_error;

json full_manifest() { return test::make_manifest(test::make_linear_probe_grid(), test::make_test_octree()); }
Manifest parse(const json& j) { return parse_manifest(j.dump(), "manifest.json"); }

TEST(LoaderManifest, ReadsTheDesignShape) {
  const Manifest m = parse(full_manifest());
  EXPECT_EQ(m.format_version, 1u);
  EXPECT_EQ(m.generator, "exitance tests");
  ASSERT_EQ(m.pages.size(), 2u);
  EXPECT_EQ(m.pages[0].file, "lightmap-0.exr");
  EXPECT_EQ(m.pages[0].width, uint32_t(test::kPage0Width));
  EXPECT_EQ(m.pages[0].height, uint32_t(test::kPage0Height));
  EXPECT_EQ(m.pages[0].channels, (std::vector<std::string>{"A", "B", "G", "R"}));
  ASSERT_EQ(m.instances.size(), 2u);
  EXPECT_EQ(m.instances[1].node, 3u);
  EXPECT_EQ(m.instances[1].name, "Wall");
  EXPECT_EQ(m.instances[1].mesh, 1u);
  EXPECT_EQ(m.instances[1].page, 1u);
  EXPECT_EQ(m.instances[0].scale_offset, test::kInstance0ScaleOffset);
  ASSERT_TRUE(m.instances[0].rect.has_value());
  EXPECT_EQ(*m.instances[0].rect, (std::array<uint32_t, 4>{2, 2, 4, 2}));
  EXPECT_FALSE(m.instances[1].rect.has_value());
  ASSERT_TRUE(m.probes.has_value());
  EXPECT_EQ(m.probes->file, "probes.bin");
  EXPECT_EQ(m.probes->origin, (std::array<float, 3>{-1, 0, 2}));
  EXPECT_EQ(m.probes->spacing, (std::array<float, 3>{0.5f, 1, 2}));
  EXPECT_EQ(m.probes->counts, (std::array<uint32_t, 3>{3, 2, 2}));
  EXPECT_EQ(m.probes->sh_order, 2u);
  ASSERT_TRUE(m.svo.has_value());
  EXPECT_EQ(m.svo->bounds_min, (std::array<float, 3>{0, 0, 0}));
  EXPECT_EQ(m.svo->bounds_max, (std::array<float, 3>{8, 8, 8}));
  EXPECT_EQ(m.svo->depth, 2u);
}

TEST(LoaderManifest, ProbesAndSvoAreOptional) {
  json j = full_manifest();
  j.erase("probes");
  j["svo"] = nullptr;
  const Manifest m = parse(j);
  EXPECT_FALSE(m.probes.has_value());
  EXPECT_FALSE(m.svo.has_value());
}

TEST(LoaderManifest, OtherVersionsAreRefusedByName) {
  json j = full_manifest();
  j["format_version"] = 2;
  expect_format_error([&] { parse(j); }, "manifest.json: format version 2 is newer than this loader (1)");
  j["format_version"] = 0;
  expect_format_error([&] { parse(j); }, "manifest.json: format version 0 is older than this loader supports (1)");
  j["format_version"] = "1";
  expect_format_error([&] { parse(j); }, "manifest.json: format_version: expected an integer, got string");
}

TEST(LoaderManifest, NotJsonIsRefused) {
  expect_format_error([] { parse_manifest("{\"format_version\": 1,", "manifest.json"); }, "manifest.json: not valid JSON");
  expect_format_error([] { parse_manifest("", "manifest.json"); }, "not valid JSON");
  expect_format_error([] { parse_manifest("[1, 2]", "manifest.json"); }, "top level: expected an object, got array");
  expect_format_error([] { parse_manifest(std::string(100000, '['), "manifest.json"); }, "not valid JSON");
}

struct EditCase {
  const char* name;
  void (*edit)(json&);
  const char* expected;
};

const EditCase kEditCases[] = {
    {"no pages", [](json& j) { j.erase("pages"); }, "manifest.json: pages: missing"},
    {"pages not an array", [](json& j) { j["pages"] = json::object(); }, "pages: expected an array, got object"},
    {"page not an object", [](json& j) { j["pages"][1] = 7; }, "pages[1]: expected an object, got number"},
    {"width as string", [](json& j) { j["pages"][0]["width"] = "8"; }, "pages[0].width: expected an integer, got string"},
    {"width zero", [](json& j) { j["pages"][0]["width"] = 0; }, "pages[0].width: 0 is outside 1..65536"},
    {"height negative", [](json& j) { j["pages"][0]["height"] = -4; }, "pages[0].height: -4 is negative"},
    {"height fractional", [](json& j) { j["pages"][0]["height"] = 4.5; }, "pages[0].height: expected an integer, got number"},
    {"channel not a string", [](json& j) { j["pages"][0]["channels"][2] = 1; }, "pages[0].channels[2]: expected a string"},
    {"absolute file", [](json& j) { j["pages"][0]["file"] = "/etc/passwd"; }, "pages[0].file: \"/etc/passwd\" is not a path relative"},
    {"escaping file", [](json& j) { j["pages"][0]["file"] = "../x.exr"; }, "pages[0].file: \"../x.exr\" leaves the bundle folder"},
    {"empty file", [](json& j) { j["pages"][0]["file"] = ""; }, "pages[0].file: empty file name"},
    {"nul in file", [](json& j) { j["pages"][0]["file"] = std::string("a\0b", 3); }, "pages[0].file: contains a NUL"},
    {"no instances", [](json& j) { j.erase("instances"); }, "instances: missing"},
    {"instance page out of range", [](json& j) { j["instances"][1]["page"] = 2; }, "instances[1].page: 2 is not a page (2 pages)"},
    {"instance page huge", [](json& j) { j["instances"][0]["page"] = 1e30; }, "instances[0].page: expected an integer"},
    {"instance name missing", [](json& j) { j["instances"][0].erase("name"); }, "instances[0].name: missing"},
    {"scale_offset short", [](json& j) { j["instances"][0]["scale_offset"] = {1, 1, 0}; }, "instances[0].scale_offset: expected 4 elements, got 3"},
    {"scale_offset overflow", [](json& j) { j["instances"][0]["scale_offset"][0] = 1e300; }, "instances[0].scale_offset[0]: not a finite 32-bit float"},
    {"scale_offset null", [](json& j) { j["instances"][0]["scale_offset"][3] = nullptr; }, "instances[0].scale_offset[3]: expected a number, got null"},
    {"rect wrong", [](json& j) { j["instances"][0]["rect"] = "x"; }, "instances[0].rect: expected an array, got string"},
    {"node negative", [](json& j) { j["instances"][0]["node"] = -1; }, "instances[0].node: -1 is negative"},
    {"probes not an object", [](json& j) { j["probes"] = 3; }, "probes: expected an object, got number"},
    {"probe counts zero", [](json& j) { j["probes"]["counts"][1] = 0; }, "probes.counts[1]: 0 is outside 1.."},
    {"probe counts overflow", [](json& j) { j["probes"]["counts"] = {65536, 65536, 65536}; }, "probes.counts: more than 67108864 probes"},
    {"probe spacing zero", [](json& j) { j["probes"]["spacing"][2] = 0; }, "probes.spacing[2]: not positive"},
    {"probe origin missing", [](json& j) { j["probes"].erase("origin"); }, "probes.origin: missing"},
    {"sh order", [](json& j) { j["probes"]["sh_order"] = 3; }, "probes.sh_order: 3 is outside 2..2"},
    {"svo depth", [](json& j) { j["svo"]["depth"] = 17; }, "svo.depth: 17 is outside 0..16"},
    {"svo bounds shape", [](json& j) { j["svo"]["bounds"] = {0, 0, 0}; }, "svo.bounds: expected 2 elements, got 3"},
    {"svo bounds inverted", [](json& j) { j["svo"]["bounds"][1][0] = -1; }, "svo.bounds: maximum not above minimum"},
    {"svo file type", [](json& j) { j["svo"]["file"] = json::array(); }, "svo.file: expected a string, got array"},
};

TEST(LoaderManifest, EachWrongFieldIsRefusedByName) {
  for (const EditCase& c : kEditCases) {
    SCOPED_TRACE(c.name);
    json j = full_manifest();
    c.edit(j);
    expect_format_error([&] { parse(j); }, c.expected);
  }
}


// One schema for reading and writing (formats/bundle_manifest.h): what is read writes back and
// reads again to the same manifest, including the optional blocks the loader does not use.
TEST(BundleManifest, WriterAndReaderRoundTrip) {
  json j = full_manifest();
  j["input"] = {{"file", "scene.gltf"}, {"sha256", std::string(64, 'a')}};
  j["settings"] = {{"backend", "vulkan"}, {"spp", 64}, {"seed", 7}, {"bounces", -1}, {"probes", "none"},
                   {"voxel_resolution", 64}, {"padding", 3}, {"sky", "0.1,0.2,0.3"}};
  j["scene"] = {{"file", "scene.bin"}, {"format_version", 1}, {"bytes", 1234}};
  j["stats"] = {{"rays", 99}, {"seconds", {{"lighting", 0.5}}}};
  const Manifest first = parse(j);
  ASSERT_TRUE(first.settings.has_value());
  EXPECT_EQ(first.settings->spp, 64u);
  EXPECT_EQ(first.settings->seed, 7u);
  EXPECT_EQ(first.settings->padding, 3u);
  EXPECT_FALSE(first.settings->probe_spacing.has_value());
  EXPECT_EQ(first.settings->voxel_resolution, std::optional<uint32_t>(64));
  EXPECT_EQ(first.settings->probe_spp, 512u);  // absent: bake's default
  ASSERT_TRUE(first.scene.has_value());
  EXPECT_EQ(first.scene->bytes, 1234u);
  EXPECT_EQ(json::parse(first.stats_json)["rays"], 99);

  const std::string written = formats::write_bundle_manifest(first);
  const Manifest second = parse_manifest(written, "written");
  EXPECT_EQ(formats::write_bundle_manifest(second), written);
  EXPECT_EQ(json::parse(written)["units"]["lightmap"], "irradiance_over_pi");
  EXPECT_EQ(second.instances[0].scale_offset, first.instances[0].scale_offset);
  EXPECT_EQ(second.probes->counts, first.probes->counts);
  EXPECT_EQ(second.svo->bounds_max, first.svo->bounds_max);
  EXPECT_EQ(second.settings->sky, "0.1,0.2,0.3");
}

// Generated lightmap UVs (issue 13): "lightmap_uv": "generate" and the meshes that got them.
TEST(BundleManifest, GeneratedLightmapUvsRoundTrip) {
  json j = full_manifest();
  j["settings"] = {{"lightmap_uv", "generate"}, {"generated_uv_meshes", {0, 3}}};
  const Manifest first = parse(j);
  ASSERT_TRUE(first.settings.has_value());
  EXPECT_TRUE(first.settings->lightmap_uv_generate);
  EXPECT_EQ(first.settings->generated_uv_meshes, (std::vector<uint32_t>{0, 3}));
  const std::string written = formats::write_bundle_manifest(first);
  EXPECT_EQ(json::parse(written)["settings"]["lightmap_uv"], "generate");
  const Manifest second = parse_manifest(written, "written");
  EXPECT_EQ(second.settings->generated_uv_meshes, first.settings->generated_uv_meshes);
  j["settings"] = {{"lightmap_uv", 1}};
  const Manifest numbered = parse(j);
  EXPECT_FALSE(numbered.settings->lightmap_uv_generate);
  EXPECT_EQ(numbered.settings->lightmap_uv, 1u);
  EXPECT_TRUE(numbered.settings->generated_uv_meshes.empty());
}

TEST(BundleManifest, TheWriterRefusesWhatTheReaderWould) {
  Manifest m = parse(full_manifest());
  m.instances[0].scale_offset[2] = std::numeric_limits<float>::quiet_NaN();
  expect_format_error([&] { formats::write_bundle_manifest(m); }, "instances[0].scale_offset[2]: expected a number, got null");
  m = parse(full_manifest());
  m.instances[1].page = 5;
  expect_format_error([&] { formats::write_bundle_manifest(m); }, "instances[1].page: 5 is not a page (2 pages)");
  m = parse(full_manifest());
  m.stats_json = "[1, 2]";
  expect_format_error([&] { formats::write_bundle_manifest(m); }, "manifest.json: stats: expected an object, got array");
}

TEST(BundleManifest, SettingsAndSceneFieldsAreCheckedByName) {
  const auto refused = [](const char* key, const json& value, const std::string& message) {
    json j = full_manifest();
    j[key] = value;
    expect_format_error([&] { parse(j); }, message);
  };
  refused("settings", {{"spp", "many"}}, "manifest.json: settings.spp: expected an integer, got string");
  refused("settings", {{"bounces", -2}}, "settings.bounces: -2 is outside -1..2147483647");
  refused("settings", {{"probes", "some"}}, "settings.probes: expected a number or \"none\"");
  refused("settings", {{"backend", "metal"}}, "settings.backend: \"metal\" is not cpu or vulkan");
  refused("settings", {{"integrator", "photons"}}, "settings.integrator: \"photons\" is not path or bounces");
  refused("settings", {{"target_error", -0.5}}, "settings.target_error: negative");
  refused("settings", json::array(), "settings: expected an object, got array");
  refused("settings", {{"lightmap_uv", "auto"}}, "settings.lightmap_uv: expected 0, 1 or \"generate\"");
  refused("settings", {{"lightmap_uv", 2}}, "settings.lightmap_uv: 2 is outside 0..1");
  refused("settings", {{"generated_uv_meshes", 3}}, "settings.generated_uv_meshes: expected an array, got number");
  refused("settings", {{"generated_uv_meshes", {1, -1}}}, "settings.generated_uv_meshes[1]:");
  refused("scene", {{"file", "../scene.bin"}, {"format_version", 1}, {"bytes", 10}}, "scene.file: \"../scene.bin\" leaves the bundle folder");
  refused("scene", {{"file", "scene.bin"}, {"bytes", 10}}, "scene.format_version: missing");
  refused("scene", {{"skipped", ""}}, "scene.skipped: empty reason");
  refused("input", {{"file", "a.gltf"}, {"sha256", "xyz"}}, "input.sha256: not 64 lowercase hexadecimal digits");
  refused("relight", "done", "relight: expected an object, got string");
  json j = full_manifest();
  j["scene"] = {{"skipped", "textures are not stored by version 1"}};
  const Manifest m = parse(j);
  ASSERT_TRUE(m.scene.has_value());
  EXPECT_TRUE(m.scene->file.empty());
  EXPECT_EQ(m.scene->skipped, "textures are not stored by version 1");
}

// "preview" (bake --preview): page PNGs, one per page, and views with their cameras; round trip
// and every field checked by name.
json preview_block() {
  return {{"pages", {"preview/lightmap-0.png", "preview/lightmap-1.png"}},
          {"views",
           {{{"file", "preview/Camera.png"}, {"camera", "Camera"}, {"look_from", {0, 1, 5}}, {"look_at", {0, 1, 4}},
             {"up", {0, 1, 0}}, {"yfov", 0.8}, {"width", 512}, {"height", 384}}}}};
}

TEST(BundleManifest, PreviewRoundTripsAndIsCheckedByName) {
  json j = full_manifest();
  j["preview"] = preview_block();
  const Manifest first = parse(j);
  ASSERT_TRUE(first.preview.has_value());
  ASSERT_EQ(first.preview->pages.size(), 2u);
  ASSERT_EQ(first.preview->views.size(), 1u);
  EXPECT_EQ(first.preview->views[0].camera, "Camera");
  EXPECT_EQ(first.preview->views[0].height, 384u);
  const std::string written = formats::write_bundle_manifest(first);
  EXPECT_EQ(formats::write_bundle_manifest(parse_manifest(written, "written")), written);
  EXPECT_FALSE(parse(full_manifest()).preview.has_value());

  j["preview"] = {{"pages", {"preview/lightmap-0.png", "preview/lightmap-1.png"}}, {"views", json::array()},
                  {"views_skipped", "no scene.bin"}};
  EXPECT_EQ(parse(j).preview->views_skipped, "no scene.bin");

  const std::pair<void (*)(json&), const char*> refused[] = {
      {[](json& p) { p["pages"].erase(1); }, "preview.pages: expected 2 elements, got 1"},
      {[](json& p) { p["pages"][0] = "../x.png"; }, "preview.pages[0]: \"../x.png\" leaves the bundle folder"},
      {[](json& p) { p.erase("views"); }, "preview.views: missing"},
      {[](json& p) { p["views"][0]["yfov"] = 3.5; }, "preview.views[0].yfov: not in (0, pi)"},
      {[](json& p) { p["views"][0]["width"] = 0; }, "preview.views[0].width: 0 is outside 1..16384"},
      {[](json& p) { p["views"][0]["camera"] = 3; }, "preview.views[0].camera: expected a string, got number"},
      {[](json& p) { p["views"][0]["look_at"] = {0, 1, 5}; }, "preview.views[0].look_at: equals look_from"},
      {[](json& p) { p["views"][0]["up"] = {0, 0, 0}; }, "preview.views[0].up: zero vector"},
      {[](json& p) { p["views_skipped"] = "why"; }, "preview: both views and a reason there are none"},
      {[](json& p) { p = 5; }, "preview: expected an object, got number"},
  };
  for (const auto& [edit, message] : refused) {
    SCOPED_TRACE(message);
    json bad = full_manifest();
    bad["preview"] = preview_block();
    edit(bad["preview"]);
    expect_format_error([&] { parse(bad); }, message);
  }
}

json light_layers_block() {
  return {{"count", 5}, {"punctual", 2}, {"files", {"light-layers-0.exr", "light-layers-1.exr"}}, {"units", "irradiance_over_pi"}};
}

TEST(BundleManifest, LightLayersRoundTripAndAreCheckedByName) {
  json j = full_manifest();
  j["light_layers"] = light_layers_block();
  const Manifest first = parse(j);
  ASSERT_TRUE(first.light_layers.has_value());
  EXPECT_EQ(first.light_layers->count, 5u);
  EXPECT_EQ(first.light_layers->punctual, 2u);
  ASSERT_EQ(first.light_layers->files.size(), 2u);
  EXPECT_EQ(first.light_layers->files[1], "light-layers-1.exr");
  const std::string written = formats::write_bundle_manifest(first);
  EXPECT_EQ(formats::write_bundle_manifest(parse_manifest(written, "written")), written);
  EXPECT_FALSE(parse(full_manifest()).light_layers.has_value());

  const std::pair<void (*)(json&), const char*> refused[] = {
      {[](json& l) { l["count"] = 0; }, "light_layers.count: 0 is outside 1..256"},
      {[](json& l) { l["count"] = 257; }, "light_layers.count: 257 is outside 1..256"},
      {[](json& l) { l["punctual"] = 5; }, "light_layers.punctual: 5 is outside 0..4"},
      {[](json& l) { l.erase("punctual"); }, "light_layers.punctual: missing"},
      {[](json& l) { l["files"].erase(1); }, "light_layers.files: expected 2 elements, got 1"},
      {[](json& l) { l["files"][1] = "light-layers-0.exr"; }, "light_layers.files[1]: \"light-layers-0.exr\" is listed twice"},
      {[](json& l) { l["files"][0] = "/tmp/x.exr"; }, "light_layers.files[0]: \"/tmp/x.exr\" is not a path relative to the bundle"},
      {[](json& l) { l = "all"; }, "light_layers: expected an object, got string"},
  };
  for (const auto& [edit, message] : refused) {
    SCOPED_TRACE(message);
    json bad = full_manifest();
    bad["light_layers"] = light_layers_block();
    edit(bad["light_layers"]);
    expect_format_error([&] { parse(bad); }, message);
  }
}

}  // namespace
}  // namespace exitance::loader
