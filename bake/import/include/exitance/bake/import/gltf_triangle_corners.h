// A primitive's triangle corners (3 vertex indices per triangle) for TRIANGLES, TRIANGLE_STRIP and
// TRIANGLE_FAN, in the order the importer numbers a mesh's triangles (and its generated UVs).
#pragma once
#include <cstdint>
#include <vector>

#include <tiny_gltf.h>

namespace exitance {

inline std::vector<uint32_t> triangle_corners(int mode, const std::vector<uint32_t>& indices) {
  std::vector<uint32_t> out;
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    out.assign(indices.begin(), indices.begin() + long(indices.size() / 3 * 3));
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (size_t i = 2; i < indices.size(); ++i) {
      if (i % 2 == 0) out.insert(out.end(), {indices[i - 2], indices[i - 1], indices[i]});
      else out.insert(out.end(), {indices[i - 1], indices[i - 2], indices[i]});
    }
  } else {  // fan
    for (size_t i = 2; i < indices.size(); ++i) out.insert(out.end(), {indices[0], indices[i - 1], indices[i]});
  }
  return out;
}

}  // namespace exitance
