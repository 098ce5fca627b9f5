// svo.bin: the sparse voxel octree on disk (layout in formats/svo_format.md). Writers validate the
// octree first; readers validate every field and the whole tree structure before returning, so
// svo_find_node and svo_node_exitance never read out of bounds on an octree they return.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "exitance/formats/format_error.h"
#include "exitance/formats/sparse_voxel_octree.h"

namespace exitance::formats {

inline constexpr char kSvoMagic[8] = {'E', 'X', 'S', 'V', 'O', '\0', '\0', '\0'};
constexpr uint32_t kSvoFormatVersion = 1;
constexpr uint32_t kSvoHeaderSize = 72;
constexpr uint32_t kSvoNodeRecordSize = 28;
// Refused above this many nodes (7.5 GB of records): a corrupt count must not become a huge
// allocation, and node indices stay far from the kSvoNoParent sentinel.
constexpr uint64_t kMaxSvoNodeCount = uint64_t(1) << 28;

// Throws FormatError naming the first node or field that is wrong. Checks: finite origin, size,
// exitance_scale; depth <= kSvoMaxDepth; level_begin shape and monotonicity; per node its level,
// flags (leaf iff level == depth, no undefined bits), finite halves, and that the children of each
// level are contiguous, in breadth-first order, inside the next level, and point back at their parent.
void validate_octree(const SparseVoxelOctree& svo, const std::string& name_for_errors);

// The exact bytes of svo.bin for an octree; throws FormatError if the octree is invalid.
std::vector<uint8_t> encode_svo(const SparseVoxelOctree& svo);
void write_svo_file(const std::string& path, const SparseVoxelOctree& svo);

// Throws FormatError (FileAccessError when the file cannot be read at all).
SparseVoxelOctree read_svo(const uint8_t* data, size_t size, const std::string& name_for_errors);
SparseVoxelOctree read_svo_file(const std::string& path);

}  // namespace exitance::formats
