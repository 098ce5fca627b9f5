#include "exitance/bake/command/bake_pipeline.h"

#include <chrono>
#include <filesystem>
#include <optional>
#include <type_traits>

#include "exitance/bake/bundle/write_bundle.h"
#include "exitance/bake/command/bake_stages.h"

namespace exitance {

namespace {

using json = nlohmann::json;

// stats.seconds: one lap per stage, each from the end of the stage before, so the laps add up to
// the whole run.
class StageClock {
 public:
  template <class Stage>
  auto time(const char* stage_name, Stage&& stage) -> decltype(stage()) {
    if constexpr (std::is_void_v<decltype(stage())>) {
      stage();
      seconds_[stage_name] = lap();
    } else {
      auto result = stage();
      seconds_[stage_name] = lap();
      return result;
    }
  }
  const json& seconds() const { return seconds_; }

 private:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return seconds;
  }
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
  json seconds_ = json::object();
};

json run_report(const WrittenBundle& bundle, const json& seconds) {
  json report = bundle.stats;
  report["seconds"] = seconds;
  report["output"] = std::filesystem::absolute(bundle.folder).string();
  report["pages"] = bundle.pages;
  return report;
}

}  // namespace

json run_bake(const BakeOptions& options, Diagnostics& diagnostics) {
  // Offline stage (DESIGN §1): scene, atlas, texel G-buffer, the BVHs, the backend that will light them.
  StageClock clock;
  std::vector<MeshWithoutLightmapUvs> without_lightmap_uvs;
  Scene imported = clock.time("import", [&] { return import_stage(options, diagnostics, without_lightmap_uvs); });
  std::vector<MeshUvReport> generated_uvs;
  if (!without_lightmap_uvs.empty())
    generated_uvs = clock.time("uv_generation", [&] {
      return uv_generation_stage(imported, without_lightmap_uvs, options, diagnostics);
    });
  const AtlasLayout layout = clock.time("layout", [&] { return layout_stage(imported, options, diagnostics); });
  TexelGBuffer gbuffer = clock.time("raster", [&] { return raster_stage(imported, layout, options, diagnostics); });
  const SceneForLighting scene =
      clock.time("bvh", [&] { return build_lighting_scene_stage(std::move(imported), options); });
  const std::shared_ptr<const Integrator> backend =
      clock.time("backend", [&] { return backend_stage(scene, options, diagnostics); });
  const size_t unoccluded = clock.time("unocclude", [&] { return unocclude_stage(scene, gbuffer); });
  const GeometryCheckReport geometry =
      clock.time("checks", [&] { return scene_checks_stage(scene, gbuffer, options, diagnostics); });

  // Voxelize and place probes before lighting, so a bad --voxel-resolution or --probes fails before
  // the long stage.
  std::optional<VoxelizedScene> voxels;
  if (options.svo_enabled)
    voxels = clock.time("voxelize", [&] { return voxelize_stage(*scene.scene, layout, options); });
  std::optional<ProbePlacement> probes;
  if (options.probes_enabled)
    probes = clock.time("probe_placement",
                        [&] { return place_probes_stage(scene, voxels ? &*voxels : nullptr, options); });

  const PersistedSceneFile scene_file = clock.time("scene_file", [&] {
    return scene_file_stage(scene, gbuffer, layout, probes ? &*probes : nullptr, options, diagnostics);
  });

  // Lighting stage (runtime/): texels, their exitance into the octree, probes.
  const LightmapEstimate lightmap =
      clock.time("lighting", [&] { return lighting_stage(*backend, gbuffer, options, diagnostics); });
  if (voxels) clock.time("exitance", [&] { exitance_stage(*voxels, scene, gbuffer, lightmap, options); });
  std::optional<ProbeEstimate> probe_lighting;
  if (probes)
    probe_lighting =
        clock.time("probes", [&] { return probe_lighting_stage(*backend, *probes, options, diagnostics); });

  // Bundle: everything the stages produced, written at once.
  const BakeResults results{.scene = *scene.scene,
                            .layout = layout,
                            .gbuffer = gbuffer,
                            .unoccluded_texels = unoccluded,
                            .geometry = geometry,
                            .backend = *backend,
                            .voxels = voxels ? &*voxels : nullptr,
                            .probes = probes ? &*probes : nullptr,
                            .lightmap = lightmap,
                            .probe_lighting = probe_lighting ? &*probe_lighting : nullptr,
                            .scene_file = scene_file,
                            .generated_uvs = &generated_uvs};
  const WrittenBundle bundle =
      clock.time("write", [&] { return write_bundle_stage(results, clock.seconds(), diagnostics, options); });
  // After the bundle, so a failed bake writes neither.
  if (!options.write_gltf.empty()) write_gltf_stage(generated_uvs, options, diagnostics);
  return run_report(bundle, clock.seconds());
}

}  // namespace exitance
