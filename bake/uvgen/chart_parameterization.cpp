// The one translation unit that includes CGAL (it is header-only and slow to compile).
#include "chart_parameterization.h"

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

#include <algorithm>
#include <cmath>

namespace exitance::uvgen {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using VertexIndex = SurfaceMesh::Vertex_index;
namespace smp = CGAL::Surface_mesh_parameterization;

// The chart's welded vertices, ascending, and each face's corners as positions in that list.
struct ChartVertices {
  std::vector<uint32_t> welded;
  std::vector<std::array<uint32_t, 3>> faces;
};

ChartVertices chart_vertices(const WeldedMesh& mesh, const Chart& chart) {
  ChartVertices v;
  for (uint32_t t : chart.triangles)
    for (uint32_t w : mesh.triangles[t]) v.welded.push_back(w);
  std::sort(v.welded.begin(), v.welded.end());
  v.welded.erase(std::unique(v.welded.begin(), v.welded.end()), v.welded.end());
  for (uint32_t t : chart.triangles) {
    std::array<uint32_t, 3>& f = v.faces.emplace_back();
    for (size_t k = 0; k < 3; ++k)
      f[k] = uint32_t(std::lower_bound(v.welded.begin(), v.welded.end(), mesh.triangles[t][k]) - v.welded.begin());
  }
  return v;
}

double signed_area(const std::array<Point2, 3>& uv) {
  return 0.5 * ((uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[1][1] - uv[0][1]) * (uv[2][0] - uv[0][0]));
}

// LSCM on the chart as a CGAL Surface_mesh; empty when CGAL refuses the mesh or fails, or when the
// result has a non-finite UV or a folded face.
std::vector<std::array<Point2, 3>> lscm(const WeldedMesh& mesh, const Chart& chart) {
  const ChartVertices v = chart_vertices(mesh, chart);
  SurfaceMesh surface;
  std::vector<VertexIndex> handles;
  handles.reserve(v.welded.size());
  for (uint32_t w : v.welded) {
    const Point3& p = mesh.positions[w];
    handles.push_back(surface.add_vertex(Kernel::Point_3(p[0], p[1], p[2])));
  }
  for (const auto& f : v.faces)
    if (surface.add_face(handles[f[0]], handles[f[1]], handles[f[2]]) == SurfaceMesh::null_face()) return {};
  SurfaceMesh::Halfedge_index border = SurfaceMesh::null_halfedge();
  for (SurfaceMesh::Halfedge_index h : surface.halfedges())
    if (surface.is_border(h)) {
      border = h;
      break;
    }
  if (border == SurfaceMesh::null_halfedge()) return {};
  auto uv_map = surface.add_property_map<VertexIndex, Kernel::Point_2>("v:uv").first;
  smp::Error_code status = smp::ERROR_EMPTY_MESH;
  try {
    status = smp::parameterize(surface, smp::LSCM_parameterizer_3<SurfaceMesh>(), border, uv_map);
  } catch (const std::exception&) {
    return {};
  }
  if (status != smp::OK) return {};

  std::vector<std::array<Point2, 3>> corners(v.faces.size());
  double total = 0;
  for (size_t i = 0; i < v.faces.size(); ++i) {
    for (size_t k = 0; k < 3; ++k) {
      const Kernel::Point_2 q = uv_map[handles[v.faces[i][k]]];
      if (!std::isfinite(q.x()) || !std::isfinite(q.y())) return {};
      corners[i][k] = {q.x(), q.y()};
    }
    total += signed_area(corners[i]);
  }
  if (!(std::fabs(total) > 0)) return {};
  const double orientation = total > 0 ? 1 : -1;
  for (auto& c : corners) {
    if (signed_area(c) * orientation < 0) return {};  // a fold would overlap its own chart
    if (orientation < 0)
      for (Point2& q : c) q[0] = -q[0];  // mirror, so every chart keeps the faces' winding
  }
  return corners;
}

}  // namespace

FlatChart project_chart_onto_plane(const WeldedMesh& mesh, const Chart& chart) {
  // A right-handed frame (t, b, n) around the seed normal: every face within the chart's cone
  // (< 90 degrees) projects with positive area, so nothing folds.
  const Point3& n = chart.normal;
  const Point3 axis = std::fabs(n[0]) < 0.9 ? Point3{1, 0, 0} : Point3{0, 1, 0};
  Point3 t{n[1] * axis[2] - n[2] * axis[1], n[2] * axis[0] - n[0] * axis[2], n[0] * axis[1] - n[1] * axis[0]};
  const double length = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  if (length > 0)
    for (double& x : t) x /= length;
  else
    t = {1, 0, 0};
  const Point3 b{n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]};
  FlatChart flat;
  flat.corner_uv.resize(chart.triangles.size());
  for (size_t i = 0; i < chart.triangles.size(); ++i)
    for (size_t k = 0; k < 3; ++k) {
      const Point3& p = mesh.positions[mesh.triangles[chart.triangles[i]][k]];
      flat.corner_uv[i][k] = {p[0] * t[0] + p[1] * t[1] + p[2] * t[2], p[0] * b[0] + p[1] * b[1] + p[2] * b[2]};
    }
  return flat;
}

FlatChart flatten_chart(const WeldedMesh& mesh, const Chart& chart) {
  // A single face (or two) needs no solve; chart_is_disk already vetted the topology.
  if (chart.triangles.size() > 2) {
    FlatChart flat;
    flat.corner_uv = lscm(mesh, chart);
    if (!flat.corner_uv.empty()) {
      flat.lscm = true;
      return flat;
    }
  }
  return project_chart_onto_plane(mesh, chart);
}

}  // namespace exitance::uvgen
