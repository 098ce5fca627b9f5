// Indices [0, count) grouped by a key (a counting sort): group g holds, in ascending order, the i
// with key_of(i) == g, as items[start[g] .. start[g + 1]); an i whose key is >= groups is left out.
// For the texels of each page or instance (lightmap_assembly.cpp, bounce_layer_cache.cpp,
// apply_scene_edits.cpp's InstanceTexels).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace exitance {

struct GroupedIndices {
  std::vector<uint32_t> start;  // groups + 1 offsets into items
  std::vector<uint32_t> items;
};

template <class KeyOf>
GroupedIndices group_indices(size_t count, size_t groups, const KeyOf& key_of) {
  GroupedIndices g;
  g.start.assign(groups + 1, 0);
  for (size_t i = 0; i < count; ++i) {
    const size_t key = size_t(key_of(i));
    if (key < groups) ++g.start[key + 1];
  }
  for (size_t k = 0; k < groups; ++k) g.start[k + 1] += g.start[k];
  g.items.resize(g.start.back());
  std::vector<uint32_t> next(g.start.begin(), g.start.end() - 1);
  for (size_t i = 0; i < count; ++i) {
    const size_t key = size_t(key_of(i));
    if (key < groups) g.items[next[key]++] = uint32_t(i);
  }
  return g;
}

}  // namespace exitance
