// A sample scene (build/samples, EXITANCE_SAMPLE_DIR: the including test target defines it) prepared
// for lighting at `density` texels per metre, as the guiding tests read them.
#pragma once
#include <string>

#include "exitance/bake/command/prepared_scene.h"

namespace exitance::testing {

inline PreparedScene prepared_sample(const char* name, float density) {
  AtlasSettings atlas;
  atlas.texel_density = density;
  Diagnostics diagnostics;
  return prepare_scene_for_lighting(std::string(EXITANCE_SAMPLE_DIR "/") + name + ".gltf", "", atlas, diagnostics);
}

}  // namespace exitance::testing
