// Schema and cross-reference checks on the raw glTF 2.0 JSON, run before tinygltf parses it.
// tinygltf silently skips optional fields of the wrong type (a string "count", an object where an
// array belongs) and reports missing or short buffers with messages that name no element, so every
// field the importer relies on is checked here first, with the element named in the InputError.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace exitance {

// External files the document may read, as lexically normal paths (base folder joined with the
// percent-decoded uri), each with the number of bytes the loader may read from it: a buffer's
// byteLength, or an image file's size. Anything not listed must not be opened.
struct GltfExternalFiles {
  std::map<std::string, uint64_t> readable;
};

// Throws InputError(file, element, problem) for the first violation found. `base_dir` is the folder
// relative uris resolve against ("" = current folder). `glb_bin_size` is nullopt for a .gltf file;
// for a .glb it is the BIN chunk's length (0 when the file has no BIN chunk).
GltfExternalFiles validate_gltf_json(const nlohmann::json& document, const std::string& file,
                                     const std::string& base_dir, std::optional<uint64_t> glb_bin_size);

}  // namespace exitance
