// libFuzzer target: the glTF/GLB importer (bake/import: tinygltf, the JSON validation, accessors,
// materials, embedded images) on untrusted bytes. The input is written to a file (.glb when it
// starts with the GLB magic, else .gltf) in a private folder, as `bake` reads a path; external URIs
// resolve in that folder, which holds nothing else. A bad file must end in exitance::InputError;
// anything else escaping (another exception, a crash, a sanitizer report, a hang) is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "exitance/bake/diagnostics.h"
#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/input_error.h"

namespace {

const std::filesystem::path& private_folder() {
  static const std::filesystem::path folder = [] {
    auto path = std::filesystem::temp_directory_path() / ("exitance-fuzz-gltf-" + std::to_string(getpid()));
    std::filesystem::create_directories(path);
    return path;
  }();
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const std::filesystem::path file = private_folder() / (binary ? "input.glb" : "input.gltf");
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  for (bool generate : {false, true}) {
    exitance::Diagnostics diagnostics;
    exitance::ImportOptions options;
    std::vector<exitance::MeshWithoutLightmapUvs> without_lightmap_uvs;
    try {
      // First as `bake` does by default (missing lightmap UVs listed for generation), then with
      // --uv generate, which reads every mesh's triangles for bake/uvgen.
      options.generate_lightmap_uvs = generate;
      (void)exitance::import_gltf(file.string(), options, diagnostics, &without_lightmap_uvs);
    } catch (const exitance::InputError&) {
      return 0;  // refused with a message: what bad input must get
    }
  }
  return 0;
}
