// Radiant exitance M = pi * L_o (RGB) per voxel side of the sparse voxel octree (DESIGN §5, seed
// 000 ch. 4), from surface samples of the lighting stage.
//
// Each sample lands in the leaf containing it, on the side its normal faces (front when it agrees
// with the leaf's two-sided normal). A refresh deposits a complete new set of samples and then
// publishes them: with blend = 1 (double buffering) the new values replace the old ones outright;
// with 0 < blend < 1 they enter an exponential moving average. Seed 000 keeps running sums that
// never forget, so after a light changes its cache averages old and new lighting forever.
//
// store_into() filters bottom-up (a parent side is the weight-averaged children's sides, a child
// side flipped where its normal opposes the parent's) and fills top-down (a side without samples
// below it takes its parent's value), then encodes halves into the octree's nodes.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/formats/sparse_voxel_octree.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

struct ExitanceSample {
  Vec3 position;
  Vec3 normal;      // unit, the side of the surface the exitance leaves from
  Vec3 exitance;    // M = pi * L_o, RGB
  float weight = 1; // surface area the sample stands for
};

class SvoExitanceCache {
 public:
  explicit SvoExitanceCache(const formats::SparseVoxelOctree& svo);

  // Adds a sample to the pending set. Samples outside the octree or in no leaf are counted and dropped.
  void deposit(const ExitanceSample& sample);
  // Makes the pending set the published values (see the header comment); clears the pending set.
  // Sides without pending samples keep their published value.
  void publish(float blend = 1.0f);
  // Filtered, filled, half-encoded exitance into svo.nodes (same octree as the constructor's).
  void store_into(formats::SparseVoxelOctree& svo) const;

  uint64_t dropped_samples() const { return dropped_; }
  // Published exitance of a leaf side (tests): node index, side 0 = front, 1 = back.
  Vec3 published(uint32_t node, int side) const { return published_[size_t(node) * 2 + size_t(side)].value; }

 private:
  struct SideSum {
    double sum[3] = {0, 0, 0};
    double weight = 0;
  };
  struct SideValue {
    Vec3 value{0, 0, 0};
    double weight = 0;  // accumulated sample weight behind the value; 0 = never lit
  };
  const formats::SparseVoxelOctree& svo_;
  std::vector<Vec3> normals_;          // decoded node normals
  std::vector<SideSum> pending_;       // per node * 2 (leaves only are used)
  std::vector<SideValue> published_;   // per node * 2
  uint64_t dropped_ = 0;
};

}  // namespace exitance
