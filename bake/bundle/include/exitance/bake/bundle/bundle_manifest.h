// manifest.json (DESIGN §4, docs/bundle.md) from the bake's options and its stages' results. Building
// it reads and writes nothing; write_bundle_stage (write_bundle.h) writes it with the other files.
#pragma once
#include <cstddef>
#include <cstdint>
#include <future>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "exitance/bake/bake_options.h"
#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/probes/probe_placement.h"
#include "exitance/bake/raster/geometry_checks.h"
#include "exitance/bake/raster/sealed_texels.h"
#include "exitance/bake/uvgen/scene_uv_generation.h"
#include "exitance/bake/voxelize/svo_build.h"
#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/bundle/indirect_denoise.h"
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// What the stages produced, as the bundle records it, in stage order. The optional stages' entries
// are null when the options turned them off (--voxel-resolution none, --probes none).
// scene.bin as encoded by the scene-file stage, or why this scene cannot have one (the encoder's
// one-line error).
struct PersistedSceneFile {
  std::vector<uint8_t> bytes;
  std::string skipped;  // non-empty when `bytes` is
};

struct BakeResults {
  const Scene& scene;                   // import
  const AtlasLayout& layout;            // layout
  const TexelGBuffer& gbuffer;          // raster, after unocclude
  size_t unoccluded_texels;             // unocclude
  const GeometryCheckReport& geometry;  // checks
  const Integrator& backend;            // backend
  const VoxelizedScene* voxels;         // voxelize; its exitance filled by the exitance stage
  const ProbePlacement* probes;         // probe placement; coefficients filled by probe lighting
  const LightmapEstimate& lightmap;     // lighting
  const ProbeEstimate* probe_lighting;  // probe lighting (set exactly when `probes` is)
  // scene file, and the octree's exitance (valid when `voxels` is set): both read only finished
  // products, so bake_pipeline.cpp runs them on threads of their own beside the write; the write
  // waits for each where it needs it (scene.bin, svo.bin and radiance.vdb, the manifest).
  std::shared_future<PersistedSceneFile> scene_file;
  std::shared_future<void> exitance;
  const std::string& input_sha256;       // the input file's SHA-256, hashed once per run (manifest, cache key)
  const std::vector<MeshUvReport>* generated_uvs = nullptr;  // uv generation: the meshes whose UVs it made
  const SealedTexels* sealed = nullptr;  // sealed texels (found before lighting); null: not looked for
  bool sealed_skipped = false;           // the lighting stage skipped them (not --no-skip)
  const nlohmann::json* stage_cache = nullptr;  // --cache: {stage: "reused" | "computed"} (stats.cache.stages)
  // Under mpirun: {"ranks": N, "rank_work": [...]} (stats.ranks, stats.rank_work); null: one process.
  const nlohmann::json* distribution = nullptr;
  const IndirectDenoiseReport* denoise = nullptr;  // --denoise: what the filter did; null: not asked
};

// The manifest (formats/bundle_manifest.h) of the bake: `pages`: the assembled lightmap pages (the manifest lists their channels). `input_sha256`: the
// input file's hash (cache/sha256_stream.h). `seconds`: stats.seconds, the stages timed so far. `warnings`:
// how many warnings the run has given.
formats::BundleManifest build_bundle_manifest(const BakeResults& results,
                                              const std::vector<formats::LightmapImage>& pages,
                                              const std::string& input_sha256, const nlohmann::json& seconds,
                                              size_t warnings, const BakeOptions& options);

}  // namespace exitance
