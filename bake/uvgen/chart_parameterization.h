// One chart flattened to the plane: LSCM (CGAL Surface_mesh_parameterization) on a disk, else a
// projection onto the plane of the chart's seed normal. The only file that includes CGAL.
#pragma once
#include <array>
#include <vector>

#include "chart_segmentation.h"

namespace exitance::uvgen {

using Point2 = std::array<double, 2>;

struct FlatChart {
  std::vector<std::array<Point2, 3>> corner_uv;  // per chart triangle (Chart::triangles order)
  bool lscm = false;                             // false: planar projection
};

// Never returns a non-finite UV and never a flipped triangle from LSCM (it falls back to the
// projection, which cannot flip a face within the chart's cone).
FlatChart flatten_chart(const WeldedMesh& mesh, const Chart& chart);

// The projection alone (also what flatten_chart falls back to).
FlatChart project_chart_onto_plane(const WeldedMesh& mesh, const Chart& chart);

}  // namespace exitance::uvgen
