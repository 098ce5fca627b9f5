#include "svo_lookup.h"

namespace exitance::loader {

SvoExitanceResult lookup_svo_exitance(const formats::SparseVoxelOctree& svo, Point3 point, uint32_t max_level,
                                      Point3 normal) {
  SvoExitanceResult result;
  const uint32_t node = formats::svo_find_node(svo, point, max_level);
  if (node == formats::kSvoNoParent) return result;
  const std::array<float, 3> node_normal = formats::decode_octahedral_normal(svo.nodes[node].normal_oct);
  const float facing = normal[0] * node_normal[0] + normal[1] * node_normal[1] + normal[2] * node_normal[2];
  result.back_side = facing < 0;
  result.exitance = formats::svo_node_exitance(svo, node, result.back_side ? 1 : 0);
  result.found = true;
  result.node = node;
  result.level = svo.nodes[node].level;
  return result;
}

}  // namespace exitance::loader
