// The stages of `bake` in data-flow order (DESIGN §1), each a plain function from the data the
// stages before it produced (and the options) to the data it produces; run_bake (bake_pipeline.h)
// calls them in this order and times each one. The work itself is in the stage folders (bake/import,
// layout, raster, voxelize, probes, bundle) and in runtime/ (the lighting); these functions hand it
// the options, name the options in errors, and announce each stage to the progress bar.
// The bundle stage, write_bundle_stage, is in bake/bundle/write_bundle.h.
#pragma once
#include <cstddef>
#include <memory>

#include "exitance/bake/bake_options.h"
#include "exitance/bake/bundle/bundle_manifest.h"
#include "exitance/bake/diagnostics.h"
#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/probes/probe_placement.h"
#include "exitance/bake/raster/geometry_checks.h"
#include "exitance/bake/raster/sealed_texels.h"
#include "exitance/bake/uvgen/scene_uv_generation.h"
#include "exitance/bake/voxelize/svo_build.h"
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// The scene every stage after the raster shares, built once: the imported scene, Embree's BVH over
// it (unocclude, the checks, probe placement, the CPU reference) and the lighting scene with its
// BVH4 and emitter tables (every backend).
struct SceneForLighting {
  std::shared_ptr<const Scene> scene;
  std::shared_ptr<const EmbreeScene> embree;
  std::shared_ptr<const LightingScene> lighting;
};

// import: the glTF file as a Scene (validated, repairs warned about), lit by the --sky radiance; the
// meshes whose lightmap UVs must be generated (the chosen set missing, or --uv generate) are listed
// in `without_lightmap_uvs`.
Scene import_stage(const BakeOptions& options, Diagnostics& diagnostics,
                   std::vector<MeshWithoutLightmapUvs>& without_lightmap_uvs);

// uv generation: lightmap UVs for those meshes (bake/uvgen), written into the scene, packed for the
// density and page the layout stage will use. Warns per mesh whose set was missing, and about
// stretched charts.
std::vector<MeshUvReport> uv_generation_stage(Scene& scene, const std::vector<MeshWithoutLightmapUvs>& without_lightmap_uvs,
                                              const BakeOptions& options, Diagnostics& diagnostics);

// write gltf (--write-gltf): the input scene again with the generated lightmap UVs as the chosen set.
void write_gltf_stage(const std::vector<MeshUvReport>& generated_uvs, const BakeOptions& options,
                      Diagnostics& diagnostics);

// layout: one atlas rectangle per instance, at --texel-density (or the automatic density).
AtlasLayout layout_stage(const Scene& scene, const BakeOptions& options, Diagnostics& diagnostics);

// raster: the texel G-buffer, the live texels of every page.
TexelGBuffer raster_stage(const Scene& scene, const AtlasLayout& layout, const BakeOptions& options,
                          Diagnostics& diagnostics);

// bvh: the Embree scene and the lighting scene (BVH4, emitter tables) over the imported scene.
SceneForLighting build_lighting_scene_stage(Scene scene, const BakeOptions& options);

// backend: the lighting backend for --backend (a Vulkan device with the scene uploaded, or the CPU
// reference on the shared Embree scene). Throws std::runtime_error when --backend vulkan is impossible.
std::shared_ptr<const Integrator> backend_stage(const SceneForLighting& scene, const BakeOptions& options,
                                                Diagnostics& diagnostics);

// unocclude: moves texel centres inside or behind nearby geometry to the visible side, in `gbuffer`;
// returns how many moved.
size_t unocclude_stage(const SceneForLighting& scene, TexelGBuffer& gbuffer, const BakeOptions& options);

// checks: enclosed and coplanar texels, enclosed lights, unsampled emitters; one warning per kind.
GeometryCheckReport scene_checks_stage(const SceneForLighting& scene, const TexelGBuffer& gbuffer,
                                       const BakeOptions& options, Diagnostics& diagnostics);

// sealed texels: the live texels no light can reach (bake/raster/sealed_texels.h), starting from
// the checks' closed texels (their first rays are not traced again).
SealedTexels sealed_texels_stage(const SceneForLighting& scene, const TexelGBuffer& gbuffer,
                                 const GeometryCheckReport& checks, const BakeOptions& options);

// voxelize: the sparse voxel octree at --voxel-resolution (automatic: leaves about 4 texels wide).
// Throws InputError naming --voxel-resolution for a resolution it cannot build.
VoxelizedScene voxelize_stage(const Scene& scene, const AtlasLayout& layout, const BakeOptions& options);

// probe placement: the probe grid at --probes spacing, probes in solid geometry (back faces, or an
// occupied leaf of `voxels` when there is one) moved or invalid. Throws InputError naming --probes.
ProbePlacement place_probes_stage(const SceneForLighting& scene, const VoxelizedScene* voxels,
                                  const BakeOptions& options);

// scene file: scene.bin's bytes (the scene, the texel G-buffer the lighting stage will light, the
// atlas, the probe layout, the BVH4, textures, vertex colours and the sky), so exitance-relight
// reproduces this bake; a scene scene.bin cannot hold gets none and the encoder's reason (the write
// warns of it). Reports no progress: the bake runs it on a thread beside other stages.
PersistedSceneFile scene_file_stage(const SceneForLighting& scene, const TexelGBuffer& gbuffer, const AtlasLayout& layout,
                                    const ProbePlacement* probes);

// Whether the lighting stage samples adaptively on `backend_name` (BakeOptions::adaptive_request).
bool adaptive_sampling_applies(const BakeOptions& options, const std::string& backend_name);

// lighting: E/pi at every live texel on the backend; warns when samples were NaN/Inf. The texels
// marked in `skip` (when not null) are not traced: they come back with no samples.
LightmapEstimate lighting_stage(const Integrator& backend, const TexelGBuffer& gbuffer, const SealedTexels* skip,
                                const BakeOptions& options, Diagnostics& diagnostics);

// exitance: the lit texels' radiant exitance into the octree's nodes, in `voxels`.
void exitance_stage(VoxelizedScene& voxels, const SceneForLighting& scene, const TexelGBuffer& gbuffer,
                    const LightmapEstimate& lightmap, const BakeOptions& options);

// The part of a --time budget the probes may use (they run first and the texels get the rest; or,
// where they follow the texels' verdict, second with what the texels' share leaves).
constexpr double kProbeShareOfTimeBudget = 0.1;

// The probes' settings after the texels' --guiding auto measured light subpaths: every probe sample
// connects (IntegratorSettings::light_subpaths, unguided) where the scene's evidence says connections
// pay (efficiency ratio above 1 beyond kChoiceZ standard errors), else `options` as they are. The
// probes have no regions of their own to measure, so the scene's verdict is theirs.
BakeOptions probes_follow_texels(const BakeOptions& options, const LightmapEstimate& lightmap);

// probes: L2 SH of incident radiance at every usable probe on the backend (--probe-spp rays each, or
// fewer, in whole stratified sets, when `time_budget_seconds` > 0 ends them first), stored into
// `probes.grid`; warns when samples were NaN/Inf.
ProbeEstimate probe_lighting_stage(const Integrator& backend, ProbePlacement& probes, const BakeOptions& options,
                                   Diagnostics& diagnostics, double time_budget_seconds = 0);

}  // namespace exitance
