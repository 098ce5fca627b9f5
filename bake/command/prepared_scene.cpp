#include "exitance/bake/command/prepared_scene.h"

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/raster/texel_raster.h"
#include "exitance/bake/raster/unocclude.h"
#include "exitance/runtime/embree_scene.h"

namespace exitance {

PreparedScene prepare_scene_for_lighting(const std::string& path, const std::string& sky, const AtlasSettings& atlas,
                                         Diagnostics& diagnostics) {
  PreparedScene prepared;
  prepared.scene = import_gltf(path, {}, diagnostics);
  prepared.scene.sky = parse_sky_option(sky);
  const AtlasLayout layout = layout_lightmap_atlas(prepared.scene, atlas, path, diagnostics);
  prepared.gbuffer = rasterize_texel_gbuffer(prepared.scene, layout, path, diagnostics);
  const EmbreeScene embree(prepared.scene);
  unocclude_texels(embree, prepared.gbuffer);
  return prepared;
}

}  // namespace exitance
