// Bounds-checked reading of glTF accessors: every component type, normalized integers,
// byteStride, sparse substitution. Any inconsistency throws InputError naming the accessor.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace tinygltf { class Model; }

namespace exitance {

// Reads accessor `index` as `count * components` floats. Normalized integer types are
// mapped to [0,1] / [-1,1] per the glTF spec; non-normalized integers convert exactly.
// `expected_components` must match the accessor type (1 = SCALAR, 2 = VEC2, ...).
// NaN/Inf values are an InputError unless `non_finite` is Keep (for data the caller repairs, e.g. normals).
enum class NonFinite { Reject, Keep };
std::vector<float> read_accessor_floats(const tinygltf::Model& model, int index, int expected_components,
                                        const std::string& file, const std::string& usage,
                                        NonFinite non_finite = NonFinite::Reject);

// Reads an index accessor (SCALAR of UNSIGNED_BYTE/SHORT/INT).
std::vector<uint32_t> read_accessor_indices(const tinygltf::Model& model, int index, const std::string& file);

}  // namespace exitance
