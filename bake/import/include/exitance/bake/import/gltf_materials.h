// glTF materials → exitance::Material: base colour, metallic, emission (with
// KHR_materials_emissive_strength), doubleSided, textures with KHR_texture_transform.
#pragma once
#include <string>

#include <tiny_gltf.h>

#include "exitance/bake/diagnostics.h"
#include "exitance/runtime/scene.h"

namespace exitance {

// Fills scene.materials (one per glTF material, plus a default one at the end for primitives
// without a material) and scene.textures (decoded only for images a material uses).
// Returns the index of the default material.
uint32_t import_gltf_materials(const tinygltf::Model& model, const std::string& file, Scene& scene,
                               Diagnostics& diagnostics);

}  // namespace exitance
