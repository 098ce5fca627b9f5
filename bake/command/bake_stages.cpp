#include "exitance/bake/command/bake_stages.h"

#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "exitance/bake/command/backend_choice.h"
#include "exitance/bake/command/expand_lightmap_estimate.h"
#include "exitance/bake/command/gbuffer_without_skipped.h"
#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/import/gltf_lightmap_uv_writer.h"
#include "exitance/bake/import/sky_option.h"
#include "exitance/bake/input_error.h"
#include "exitance/bake/raster/texel_raster.h"
#include "exitance/bake/raster/unocclude.h"
#include "exitance/formats/probe_grid.h"
#include "exitance/formats/scene_file.h"
#include "exitance/runtime/scene_file_conversion.h"
#include "exitance/runtime/bundle/probe_results.h"
#include "exitance/runtime/bundle/texel_exitance.h"
#include "exitance/runtime/core/guiding_choice.h"
#include "exitance/runtime/core/work_share.h"
#include "exitance/runtime/cpu/bvh4_builder.h"

namespace exitance {

namespace {

void warn_about_nonfinite_samples(uint64_t count, const char* what, const BakeOptions& options,
                                  Diagnostics& diagnostics) {
  if (count > 0)
    diagnostics.warn(options.input + ": " + std::to_string(count) + " " + what +
                     " samples were NaN/Inf and were discarded (please report this scene)");
}

// The stage's share done, for the progress bar (none without one).
FractionDone stage_fraction(const BakeOptions& options, const char* stage) {
  if (!options.progress) return {};
  return [&options, stage](double fraction) { options.progress(stage, fraction, 0); };
}

}  // namespace

Scene import_stage(const BakeOptions& options, Diagnostics& diagnostics,
                   std::vector<MeshWithoutLightmapUvs>& without_lightmap_uvs) {
  options.announce_stage("import");
  Scene scene = import_gltf(options.input, options.import, diagnostics, &without_lightmap_uvs);
  scene.sky = parse_sky_option(options.sky);
  return scene;
}

std::vector<MeshUvReport> uv_generation_stage(Scene& scene, const std::vector<MeshWithoutLightmapUvs>& without_lightmap_uvs,
                                              const BakeOptions& options, Diagnostics& diagnostics) {
  if (without_lightmap_uvs.empty()) return {};
  options.announce_stage("uv generation");
  // The density and usable page side the layout stage will use (the density depends on world areas
  // only, not on UVs), so the packed gutter holds at the rectangles it lays out.
  const double density = options.atlas.texel_density > 0
                             ? options.atlas.texel_density
                             : automatic_texel_density(scene, options.atlas.max_total_texels);
  const int usable_side = options.atlas.max_page - 2 * options.atlas.padding;
  if (usable_side < 4) throw InputError(options.input, "--max-page", "is too small for the padding");
  std::vector<MeshUvReport> reports = generate_missing_lightmap_uvs(
      scene, without_lightmap_uvs, density, usable_side,
      [&](double fraction) {
        if (options.progress) options.progress("uv generation", fraction, 0);
      });
  for (const MeshUvReport& r : reports) {
    const std::string mesh = "mesh " + std::to_string(r.mesh) + (r.name.empty() ? "" : " '" + r.name + "'");
    const std::string charts = std::to_string(r.stats.charts) + (r.stats.charts == 1 ? " chart" : " charts");
    if (!r.missing_set.empty())
      diagnostics.warn(options.input + ": " + mesh + ": no " + r.missing_set + "; generated lightmap UVs: " + charts);
    if (r.stats.stretched_charts)
      diagnostics.warn(options.input + ": " + mesh + ": " + std::to_string(r.stats.stretched_charts) + " of " + charts +
                       " of the generated lightmap UVs are stretched (mean area or angle distortion above 2)");
    if (!r.stats.gutter_holds)
      diagnostics.warn(options.input + ": " + mesh + ": generated lightmap UV charts do not fit --max-page " +
                       std::to_string(options.atlas.max_page) + " with a 2-texel gap; they may bleed into each other");
  }
  return reports;
}

void write_gltf_stage(const std::vector<MeshUvReport>& generated_uvs, const BakeOptions& options,
                      Diagnostics& diagnostics) {
  options.announce_stage("write gltf");
  std::vector<MeshLightmapUvs> meshes;
  for (const MeshUvReport& r : generated_uvs) meshes.push_back({r.mesh, r.corner_uv});
  Diagnostics reload;  // the input's repairs were reported by the import already
  write_gltf_with_lightmap_uvs(options.input, options.write_gltf, options.import.lightmap_uv_set, meshes, reload);
  if (generated_uvs.empty())
    diagnostics.warn(options.input + ": --write-gltf: no mesh needed generated lightmap UVs; " + options.write_gltf +
                     " has the input's own");
}

AtlasLayout layout_stage(const Scene& scene, const BakeOptions& options, Diagnostics& diagnostics) {
  options.announce_stage("layout");
  return layout_lightmap_atlas(scene, options.atlas, options.input, diagnostics);
}

TexelGBuffer raster_stage(const Scene& scene, const AtlasLayout& layout, const BakeOptions& options,
                          Diagnostics& diagnostics) {
  options.announce_stage("raster");
  return rasterize_texel_gbuffer(scene, layout, options.input, diagnostics, stage_fraction(options, "raster"));
}

SceneForLighting build_lighting_scene_stage(Scene scene, const BakeOptions& options) {
  options.announce_stage("bvh");
  SceneForLighting built;
  built.scene = std::make_shared<const Scene>(std::move(scene));
  built.embree = std::make_shared<const EmbreeScene>(*built.scene);
  built.lighting = std::make_shared<const LightingScene>(build_lighting_scene(built.scene, build_bvh4(*built.scene)));
  return built;
}

std::shared_ptr<const Integrator> backend_stage(const SceneForLighting& scene, const BakeOptions& options,
                                                Diagnostics& diagnostics) {
  options.announce_stage("backend");
  BackendRequest request = options.backend;
  if (options.adaptive_request == AdaptiveRequest::On && request.name == "auto") {
    // Adaptive sampling exists on the CPU backend only for now (the Vulkan backend refuses it).
    request.name = "cpu";
    diagnostics.warn("--adaptive on: using the CPU reference (Embree), the only backend with adaptive sampling yet");
  }
  if (options.lighting.light_subpaths && request.name == "auto") {
    request.name = "cpu";
    diagnostics.warn("--light-paths on: using the CPU reference (Embree), the only backend with light subpaths yet");
  }
  return choose_lighting_backend(scene.lighting, scene.embree, request, diagnostics);
}

size_t unocclude_stage(const SceneForLighting& scene, TexelGBuffer& gbuffer, const BakeOptions& options) {
  options.announce_stage("unocclude");
  return unocclude_texels(*scene.embree, gbuffer, stage_fraction(options, "unocclude")).moved;
}

GeometryCheckReport scene_checks_stage(const SceneForLighting& scene, const TexelGBuffer& gbuffer,
                                       const BakeOptions& options, Diagnostics& diagnostics) {
  options.announce_stage("checks");
  GeometryCheckReport report = check_scene_geometry(*scene.scene, *scene.embree, gbuffer, stage_fraction(options, "checks"));
  for (std::string& line : describe_geometry_problems(report, *scene.scene, options.input)) diagnostics.warn(line);
  return report;
}

SealedTexels sealed_texels_stage(const SceneForLighting& scene, const TexelGBuffer& gbuffer,
                                 const GeometryCheckReport& checks, const BakeOptions& options) {
  options.announce_stage("sealed texels");
  return find_sealed_texels(*scene.scene, *scene.embree, gbuffer, &checks.closed_texels,
                            stage_fraction(options, "sealed texels"));
}

VoxelizedScene voxelize_stage(const Scene& scene, const AtlasLayout& layout, const BakeOptions& options) {
  options.announce_stage("voxelize");
  SvoBuildSettings settings;
  try {
    settings.depth = options.voxel_resolution ? svo_depth_from_resolution(options.voxel_resolution)
                                              : default_svo_depth(scene, layout.texel_density);
  } catch (const std::invalid_argument& e) {
    throw InputError(options.input, "--voxel-resolution", e.what());
  }
  VoxelizedScene voxels;
  voxels.svo = build_sparse_voxel_octree(scene, settings, &voxels.statistics);
  return voxels;
}

ProbePlacement place_probes_stage(const SceneForLighting& scene, const VoxelizedScene* voxels,
                                  const BakeOptions& options) {
  options.announce_stage("probe placement");
  ProbePlacementSettings settings;
  settings.spacing = options.probe_spacing;
  try {
    return place_probes(*scene.scene, *scene.embree, voxels ? &voxels->svo : nullptr, settings);
  } catch (const std::invalid_argument& e) {
    throw InputError(options.input, "--probes", e.what());
  }
}

bool adaptive_sampling_applies(const BakeOptions& options, const std::string& backend_name) {
  if (options.adaptive_request == AdaptiveRequest::Off) return false;
  if (options.adaptive_request == AdaptiveRequest::On) return true;
  // Under mpirun the pilot's plan is not split over ranks: auto stays off there.
  if (distributed(options.lighting.work_share)) return false;
  return backend_name == "cpu" && options.lighting.integrator == IntegratorMode::Path &&
         (options.lighting.time_budget_seconds > 0 || options.lighting.target_relative_error > 0);
}

LightmapEstimate lighting_stage(const Integrator& backend, const TexelGBuffer& gbuffer, const SealedTexels* skip,
                                const BakeOptions& options, Diagnostics& diagnostics) {
  IntegratorSettings settings = options.lighting;
  settings.adaptive = adaptive_sampling_applies(options, backend.backend_name());
  if (options.adaptive_request == AdaptiveRequest::Off && settings.target_relative_error > 0 &&
      backend.backend_name() == "cpu" && settings.integrator == IntegratorMode::Path)
    diagnostics.warn("--adaptive off: the CPU backend plans --target-error samples per texel (adaptive sampling) "
                     "all the same; the manifest's settings.adaptive says so");
  settings.progress = [&](double fraction, uint64_t rays) {
    if (options.progress) options.progress("lighting", fraction, rays);
  };
  // The backends light the texel list they are given: hand them the texels light can reach and
  // put the estimate back on the full list (sealed texels with no samples).
  LightmapEstimate estimate;
  const auto start = std::chrono::steady_clock::now();
  // The budget is the stage's: its clock starts here, so the copies around the backend and the
  // backend's own setup count against it too.
  if (settings.time_budget_seconds > 0)
    settings.budget_clock = [start] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  // Under mpirun only rank 0's estimate holds the texels (Integrator::bake): the others keep theirs as is.
  const WorkShare* share = distributed(settings.work_share);
  const bool writer = !share || share->rank() == 0;
  if (skip && skip->texels > 0) {
    LightmapEstimate traced = backend.bake(gbuffer_without_skipped(gbuffer, skip->sealed), settings);
    estimate = writer ? expand_lightmap_estimate(std::move(traced), skip->sealed) : std::move(traced);
  } else {
    estimate = backend.bake(gbuffer, settings);
  }
  // A budget is cut into passes of whole samples; when even the first pass (one sample per texel,
  // one per bounce in the per-bounce mode) does not fit, the bake keeps it and says so.
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (settings.time_budget_seconds > 0 && seconds > 1.02 * settings.time_budget_seconds) {
    char line[320];
    std::snprintf(line, sizeof line,
                  "--time: the lighting took %.3g s, %.3gx the %.3g s the budget left it: one pass of the "
                  "fewest samples the integrator takes did not fit (lower --texel-density or raise --time)",
                  seconds, seconds / settings.time_budget_seconds, settings.time_budget_seconds);
    diagnostics.warn(line);
  }
  warn_about_nonfinite_samples(estimate.nonfinite_samples, "path", options, diagnostics);
  return estimate;
}

void exitance_stage(VoxelizedScene& voxels, const SceneForLighting& scene, const TexelGBuffer& gbuffer,
                    const LightmapEstimate& lightmap, const BakeOptions& options) {
  options.announce_stage("exitance");
  fill_svo_exitance(voxels.svo, *scene.scene, gbuffer, lightmap);
}

BakeOptions probes_follow_texels(const BakeOptions& options, const LightmapEstimate& lightmap) {
  BakeOptions out = options;
  if (lightmap.guiding_auto_light_subpaths && lightmap.guiding_scene.z() > kChoiceZ) {
    out.lighting.light_subpaths = true;
    out.lighting.guiding = GuidingMode::Off;
  }
  return out;
}

ProbeEstimate probe_lighting_stage(const Integrator& backend, ProbePlacement& probes, const BakeOptions& options,
                                   Diagnostics& diagnostics, double time_budget_seconds) {
  std::vector<Vec3> positions;
  std::vector<size_t> traced;  // grid index of each traced probe
  for (size_t i = 0; i < probes.grid.probes.size(); ++i) {
    const formats::ProbeRecord& r = probes.grid.probes[i];
    if (!formats::probe_is_usable(r)) continue;
    positions.push_back({r.position[0], r.position[1], r.position[2]});
    traced.push_back(i);
  }
  IntegratorSettings settings = options.lighting;
  settings.spp = options.probe_spp;
  settings.time_budget_seconds = time_budget_seconds;
  settings.target_relative_error = 0;
  settings.adaptive = false;
  settings.progress = [&](double fraction, uint64_t rays) {
    if (options.progress) options.progress("probes", fraction, rays);
  };
  ProbeEstimate estimate = backend.bake_probes(positions, settings);
  store_probe_radiance(probes.grid, traced, estimate, options.probe_sh_window);
  warn_about_nonfinite_samples(estimate.nonfinite_samples, "probe", options, diagnostics);
  return estimate;
}

PersistedSceneFile scene_file_stage(const SceneForLighting& scene, const TexelGBuffer& gbuffer, const AtlasLayout& layout,
                                    const ProbePlacement* probes) {
  PersistedSceneFile file;
  try {
    // Two steps of about equal time at 10 M texels (bench_offline_stages): gather the records
    // (the texels' surfaces re-derived), then lay out the bytes and their checksum.
    const formats::SceneFile records = make_scene_file(*scene.scene, gbuffer, layout, probes ? &probes->grid : nullptr,
                                                       to_scene_bvh(scene.lighting->bvh));
    file.bytes = formats::encode_scene(records);
  } catch (const formats::FormatError& e) {
    file.skipped = e.what();
  }
  return file;
}

}  // namespace exitance
