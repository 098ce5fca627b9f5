#include "exitance/bake/command/prepared_scene.h"

#include "exitance/bake/command/bake_stages.h"
#include "exitance/bake/raster/unocclude.h"
#include "exitance/runtime/embree_scene.h"

namespace exitance {

PreparedScene prepare_scene_for_lighting(const std::string& path, const std::string& sky, const AtlasSettings& atlas,
                                         Diagnostics& diagnostics) {
  BakeOptions options;
  options.input = path;
  options.sky = sky;
  options.atlas = atlas;
  PreparedScene prepared;
  std::vector<MeshWithoutLightmapUvs> without_lightmap_uvs;
  prepared.scene = import_stage(options, diagnostics, without_lightmap_uvs);
  uv_generation_stage(prepared.scene, without_lightmap_uvs, options, diagnostics);
  prepared.layout = layout_stage(prepared.scene, options, diagnostics);
  prepared.gbuffer = raster_stage(prepared.scene, prepared.layout, options, diagnostics);
  const EmbreeScene embree(prepared.scene);
  unocclude_texels(embree, prepared.gbuffer);
  return prepared;
}

}  // namespace exitance
