// Two-sided normals of SVO nodes. A voxel stores exitance on both sides of one normal, so the
// normal must point along the dominant surface orientation even where opposite-facing surfaces
// share the voxel (a thin wall, a table top and its underside): a plain average would cancel to
// ~0 there and the two sides would blur into each other (seed 000, "two-sided voxels").
#pragma once
#include <cmath>
#include <cstddef>

#include "triangle_box_overlap.h"

namespace exitance {

struct WeightedNormal {
  Double3 normal;  // unit
  double weight;   // > 0 (surface area the normal stands for)
};

inline double norm(const Double3& v) { return std::sqrt(dot(v, v)); }

// Leaf rule: area-weighted 2-means clustering of the triangles' normals, seeded with N and -N where
// N is the weighted mean normal (or the heaviest triangle's normal where the mean nearly cancels),
// 4 iterations; the heavier cluster's mean is the leaf normal. Opposite-facing triangles end in
// different clusters, so a double wall keeps a normal along ±(wall normal).
inline Double3 two_means_dominant_normal(const WeightedNormal* samples, size_t count) {
  if (count == 0) return {0, 0, 1};
  Double3 mean{0, 0, 0};
  double total_weight = 0;
  size_t heaviest = 0;
  for (size_t i = 0; i < count; ++i) {
    for (int k = 0; k < 3; ++k) mean[k] += samples[i].weight * samples[i].normal[k];
    total_weight += samples[i].weight;
    if (samples[i].weight > samples[heaviest].weight) heaviest = i;
  }
  const double mean_length = norm(mean);
  Double3 centre[2];
  if (mean_length > 1e-3 * total_weight) {
    centre[0] = {mean[0] / mean_length, mean[1] / mean_length, mean[2] / mean_length};
  } else {
    centre[0] = samples[heaviest].normal;
  }
  centre[1] = {-centre[0][0], -centre[0][1], -centre[0][2]};
  double cluster_weight[2] = {0, 0};
  for (int iteration = 0; iteration < 4; ++iteration) {
    Double3 sum[2] = {{0, 0, 0}, {0, 0, 0}};
    cluster_weight[0] = cluster_weight[1] = 0;
    for (size_t i = 0; i < count; ++i) {
      const int c = dot(samples[i].normal, centre[0]) >= dot(samples[i].normal, centre[1]) ? 0 : 1;
      for (int k = 0; k < 3; ++k) sum[c][k] += samples[i].weight * samples[i].normal[k];
      cluster_weight[c] += samples[i].weight;
    }
    // An empty or self-cancelling cluster keeps its previous centre.
    for (int c = 0; c < 2; ++c) {
      const double length = norm(sum[c]);
      if (length > 0) centre[c] = {sum[c][0] / length, sum[c][1] / length, sum[c][2] / length};
    }
  }
  return cluster_weight[0] >= cluster_weight[1] ? centre[0] : centre[1];
}

// Internal-node rule: the weighted average of the children's normals after flipping each to the
// hemisphere of the heaviest child's normal. Normals are two-sided (±n describe the same surface
// orientation), so flipping loses nothing, and opposed children (the two faces of a wall split
// across octants) reinforce instead of cancelling. After flipping, every term has a non-negative
// dot product with the heaviest child's normal, so the sum cannot vanish.
inline Double3 aligned_average_normal(const WeightedNormal* children, size_t count) {
  if (count == 0) return {0, 0, 1};
  size_t heaviest = 0;
  for (size_t i = 1; i < count; ++i)
    if (children[i].weight > children[heaviest].weight) heaviest = i;
  const Double3& reference = children[heaviest].normal;
  Double3 sum{0, 0, 0};
  for (size_t i = 0; i < count; ++i) {
    const double sign = dot(children[i].normal, reference) < 0 ? -1.0 : 1.0;
    for (int k = 0; k < 3; ++k) sum[k] += sign * children[i].weight * children[i].normal[k];
  }
  const double length = norm(sum);
  if (!(length > 0)) return reference;  // only for zero weights
  return {sum[0] / length, sum[1] / length, sum[2] / length};
}

}  // namespace exitance
