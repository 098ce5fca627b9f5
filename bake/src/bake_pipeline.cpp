#include "exitance/bake/bake_pipeline.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "exitance/bake/backend_choice.h"
#include "exitance/bake/bundle_writer.h"
#include "exitance/bake/geometry_checks.h"
#include "exitance/bake/image_decode.h"
#include "exitance/bake/input_error.h"
#include "exitance/bake/lightmap_assembly.h"
#include "exitance/bake/texel_raster.h"
#include "exitance/bake/unocclude.h"
#include "exitance/runtime/embree_scene.h"

namespace exitance {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

class StageTimer {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace

Sky parse_sky_option(const std::string& value) {
  Sky sky;
  if (value.empty()) return sky;
  std::stringstream stream(value);
  std::string part;
  std::vector<float> numbers;
  bool all_numbers = true;
  while (std::getline(stream, part, ',')) {
    try {
      size_t used = 0;
      const float v = std::stof(part, &used);
      if (used != part.size()) all_numbers = false;
      numbers.push_back(v);
    } catch (...) {
      all_numbers = false;
    }
  }
  if (all_numbers && numbers.size() == 3) {
    for (float v : numbers)
      if (!std::isfinite(v) || v < 0) throw InputError(value, "--sky", "colour components must be finite and >= 0");
    sky.constant = {numbers[0], numbers[1], numbers[2]};
    return sky;
  }
  if (all_numbers) throw InputError(value, "--sky", "expected R,G,B or an image file");
  sky.environment = read_linear_image_file(value, "--sky");
  return sky;
}

json run_bake(const BakeOptions& options, Diagnostics& diagnostics) {
  StageTimer timer;
  json seconds = json::object();
  auto report = [&](const std::string& stage, double fraction, uint64_t rays) {
    if (options.progress) options.progress(stage, fraction, rays);
  };

  report("import", 0, 0);
  Scene scene = import_gltf(options.input, options.import, diagnostics);
  scene.sky = parse_sky_option(options.sky);
  seconds["import"] = timer.lap();

  report("layout", 0, 0);
  const AtlasLayout layout = layout_lightmap_atlas(scene, options.atlas, options.input, diagnostics);
  seconds["layout"] = timer.lap();

  report("raster", 0, 0);
  TexelGBuffer gbuffer = rasterize_texel_gbuffer(scene, layout, options.input, diagnostics);
  seconds["raster"] = timer.lap();

  report("bvh", 0, 0);
  const LightingBackend backend = choose_lighting_backend(scene, options.backend, diagnostics);
  seconds["bvh"] = timer.lap();
  size_t moved = 0;
  GeometryCheckReport geometry;
  {
    EmbreeScene embree(scene);
    moved = unocclude_texels(embree, gbuffer).moved;
    seconds["unocclude"] = timer.lap();
    geometry = check_scene_geometry(scene, embree, gbuffer);
    for (std::string& line : describe_geometry_problems(geometry, scene, options.input)) diagnostics.warn(line);
    seconds["checks"] = timer.lap();
  }

  IntegratorSettings lighting = options.lighting;
  lighting.progress = [&](double fraction, uint64_t rays) { report("lighting", fraction, rays); };
  const LightmapEstimate estimate = backend.bake(gbuffer, lighting);
  seconds["lighting"] = timer.lap();
  if (estimate.nonfinite_samples > 0)
    diagnostics.warn(options.input + ": " + std::to_string(estimate.nonfinite_samples) +
                     " path samples were NaN/Inf and were discarded (please report this scene)");

  report("write", 0, 0);
  AssemblyOptions assembly;
  assembly.bounce_layers = options.bounce_layers;
  assembly.dilation_texels = std::max(2, options.atlas.padding * 2);
  const std::vector<formats::LightmapImage> pages = assemble_lightmap_pages(gbuffer, estimate, assembly);

  // Statistics: mean relative standard error over live texels with signal.
  double relative_error_sum = 0;
  size_t relative_error_count = 0;
  uint64_t min_samples = gbuffer.texels.empty() ? 0 : UINT64_MAX, sample_sum = 0;
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const float mean = luminance(estimate.mean_total(i));
    const float se = std::sqrt(luminance(estimate.variance_of_mean(i)));
    if (mean > 0) relative_error_sum += se / mean, ++relative_error_count;
    min_samples = std::min<uint64_t>(min_samples, estimate.texels[i].samples);
    sample_sum += estimate.texels[i].samples;
  }

  const fs::path input_path(options.input);
  const fs::path out = options.output.empty() ? fs::path(input_path).replace_extension(".bake") : fs::path(options.output);
  json manifest;
  manifest["format_version"] = 1;
  manifest["generator"] = "exitance 0.1.0";
  manifest["input"] = {{"file", input_path.filename().string()}, {"sha256", sha256_of_file(options.input)}};
  manifest["units"] = {{"lightmap", "irradiance_over_pi"}, {"probes", "incident_radiance_sh_l2"}, {"length", "scene"}};
  manifest["settings"] = {{"backend", backend.name},
                          {"spp", options.lighting.spp},
                          {"time_budget_seconds", options.lighting.time_budget_seconds},
                          {"target_error", options.lighting.target_relative_error},
                          {"bounces", options.lighting.max_bounces},
                          {"seed", options.lighting.seed},
                          {"texel_density", layout.texel_density},
                          {"max_page", options.atlas.max_page},
                          {"padding", options.atlas.padding},
                          {"lightmap_uv", options.import.lightmap_uv_set},
                          {"russian_roulette_start", options.lighting.russian_roulette_start},
                          {"safety_bounce_cap", options.lighting.safety_bounce_cap},
                          {"sky", options.sky}};
  json page_list = json::array();
  std::vector<std::string> layer_channels;
  for (size_t p = 0; p < pages.size(); ++p) {
    json channels = json::array();
    for (const auto& [name, data] : pages[p].channels) channels.push_back(name);
    page_list.push_back({{"file", "lightmap-" + std::to_string(p) + ".exr"},
                         {"width", pages[p].width},
                         {"height", pages[p].height},
                         {"channels", channels}});
  }
  manifest["pages"] = page_list;
  json instances = json::array();
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const InstanceRect& r = layout.rects[i];
    instances.push_back({{"node", scene.instances[i].node},
                         {"name", scene.instances[i].name},
                         {"mesh", scene.instances[i].mesh},
                         {"page", r.page},
                         {"scale_offset", {r.scale_offset[0], r.scale_offset[1], r.scale_offset[2], r.scale_offset[3]}},
                         {"rect", {r.x, r.y, r.width, r.height}}});
  }
  manifest["instances"] = instances;
  const double lighting_seconds = estimate.seconds;
  json stats;
  stats["seconds"] = seconds;
  stats["device"] = backend.device;
  stats["triangles"] = scene.triangle_count();
  stats["instances"] = scene.instances.size();
  stats["live_texels"] = gbuffer.texels.size();
  stats["rays"] = estimate.rays;
  stats["rays_per_second"] = lighting_seconds > 0 ? double(estimate.rays) / lighting_seconds : 0.0;
  stats["samples_per_texel"] = {{"min", min_samples},
                                {"mean", gbuffer.texels.empty() ? 0.0 : double(sample_sum) / double(gbuffer.texels.size())}};
  stats["estimated_relative_error"] = relative_error_count ? relative_error_sum / double(relative_error_count) : 0.0;
  stats["unoccluded_texels"] = moved;
  stats["enclosed_texels"] = geometry.enclosed_texels;
  stats["coplanar_texels"] = geometry.coplanar_texels;
  stats["enclosed_lights"] = geometry.enclosed_lights;
  stats["nonfinite_samples"] = estimate.nonfinite_samples;
  stats["skipped"] = {{"texels_outside_charts", gbuffer.skipped_texels},
                      {"probes", "not implemented yet"},
                      {"svo", "not implemented yet"}};
  stats["warnings"] = diagnostics.warnings.size();
  manifest["stats"] = stats;

  write_bundle_atomically(out, [&](const fs::path& dir) {
    for (size_t p = 0; p < pages.size(); ++p)
      formats::write_lightmap_exr((dir / ("lightmap-" + std::to_string(p) + ".exr")).string(), pages[p]);
    std::ofstream file(dir / "manifest.json");
    file << manifest.dump(2) << "\n";
    if (!file) throw std::runtime_error("cannot write " + (dir / "manifest.json").string());
  });
  seconds["write"] = timer.lap();
  json result = stats;
  result["seconds"] = seconds;
  result["output"] = fs::absolute(out).string();
  result["pages"] = pages.size();
  return result;
}

}  // namespace exitance
