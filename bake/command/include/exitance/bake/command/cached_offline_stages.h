// The offline stages through the per-stage cache (issue 12, "Skip"; bake/cache/stage_cache.h):
// each call restores its stage's products when the cache holds them under the stage's key
// (stage_cache_keys.h) and repeats the warnings the stage gave, or runs the stage (bake_stages.h)
// and stores what it made. Without --cache every call just runs its stage.
//
// The products are stored with their own codecs: the G-buffer as scene.bin's texel records
// (texel_gbuffer_codec.h, bit for bit, after unocclude), the octree as svo.bin, the probe grid as
// probes.bin; the layout, the check counts and the texel masks as JSON and raw bytes.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "exitance/bake/cache/stage_cache.h"
#include "exitance/bake/cache/stage_cache_keys.h"
#include "exitance/bake/command/bake_stages.h"

namespace exitance {

class CachedOfflineStages {
 public:
  // `scene`: the imported scene after UV generation (the keys are taken from it here).
  CachedOfflineStages(const Scene& scene, const BakeOptions& options);

  AtlasLayout layout(const Scene& scene, Diagnostics& diagnostics);
  // The G-buffer: restored after unocclude, or rasterized (and unoccluded by unocclude()).
  TexelGBuffer raster(const Scene& scene, const AtlasLayout& layout, Diagnostics& diagnostics);
  // Moves texels out of geometry, unless raster() restored them moved; then stores the G-buffer.
  size_t unocclude(const SceneForLighting& scene, TexelGBuffer& gbuffer, const AtlasLayout& layout,
                   Diagnostics& diagnostics);
  GeometryCheckReport checks(const SceneForLighting& scene, const TexelGBuffer& gbuffer, Diagnostics& diagnostics);
  SealedTexels sealed_texels(const SceneForLighting& scene, const TexelGBuffer& gbuffer,
                             const GeometryCheckReport& checks, Diagnostics& diagnostics);
  VoxelizedScene voxelize(const Scene& scene, const AtlasLayout& layout, Diagnostics& diagnostics);
  ProbePlacement place_probes(const SceneForLighting& scene, const VoxelizedScene* voxels, Diagnostics& diagnostics);

  // stats.cache.stages: {stage: "reused" | "computed"}; empty without --cache.
  const nlohmann::json& outcomes() const { return outcomes_; }
  const StageCacheKeys& keys() const { return keys_; }

 private:
  const BakeOptions& options_;
  std::optional<StageCache> cache_;
  StageCacheKeys keys_;
  nlohmann::json outcomes_ = nlohmann::json::object();
  // The G-buffer stage spans raster() and unocclude(): what raster() found or warned.
  std::optional<size_t> restored_unoccluded_;
  std::vector<std::string> raster_warnings_;
};

}  // namespace exitance
