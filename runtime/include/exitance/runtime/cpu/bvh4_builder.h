// The offline stage's BVH4 for every backend (core/bvh4.h): Embree's rtcBuildBVH (SAH with spatial
// splits, up to 4 triangles per leaf) with our node callbacks, flattened depth-first. A triangle
// may be split into fragments in several leaves (at most twice as many leaf slots as triangles),
// each leaf's box holding only its fragment. Triangles with non-finite vertices are left out
// (Embree's own scene never hits them either).
#pragma once
#include "exitance/runtime/core/bvh4.h"
#include "exitance/runtime/scene.h"

namespace exitance {

Bvh4 build_bvh4(const Scene& scene);

}  // namespace exitance
