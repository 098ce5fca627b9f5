#include "exitance/bake/uvgen/lightmap_uv_generation.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <thread>

#include "chart_halving.h"
#include "chart_packing.h"
#include "progress_steps.h"
#include "chart_parameterization.h"
#include "chart_segmentation.h"
#include "uv_distortion.h"
#include "welded_mesh.h"

namespace exitance {
namespace {

using uvgen::Point2;
using uvgen::Point3;

const double kCurvedChartCos = std::cos(10 * std::numbers::pi / 180);

double uv_area(const std::array<Point2, 3>& uv) {
  return 0.5 * std::fabs((uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[1][1] - uv[0][1]) * (uv[2][0] - uv[0][0]));
}

}  // namespace

GeneratedUvs generate_lightmap_uvs(std::span<const Vec3> positions, std::span<const uint32_t> indices,
                                   const UvGenerationSettings& settings) {
  if (indices.size() % 3) throw std::invalid_argument("index count is not a multiple of 3");
  uvgen::ProgressSteps progress(settings.progress);
  progress.at(0);
  const uvgen::WeldedMesh mesh = uvgen::weld_by_position(positions, indices);
  const size_t triangle_count = mesh.triangle_count();
  uvgen::SegmentationSettings segmentation;
  segmentation.cone_degrees = settings.chart_cone_degrees;
  segmentation.sharp_edge_degrees = settings.sharp_edge_degrees;
  segmentation.max_chart_triangles = settings.max_chart_triangles;
  const std::vector<int32_t> neighbour = uvgen::face_neighbours(mesh, segmentation.sharp_edge_degrees);
  uvgen::ChartSplitter splitter(mesh, neighbour, segmentation.max_chart_triangles);

  GeneratedUvs out;
  UvGenerationStats& stats = out.stats;
  stats.triangles = triangle_count;

  // Flatten a chart, then scale it so its UV area equals its 3-D area (uniform texel density).
  auto flatten_scaled = [&](const uvgen::Chart& chart) {
    uvgen::FlatChart flat = uvgen::flatten_chart(mesh, chart);
    double area_3d = 0, area_uv = 0;
    for (size_t i = 0; i < chart.triangles.size(); ++i) {
      area_3d += mesh.areas[chart.triangles[i]];
      area_uv += uv_area(flat.corner_uv[i]);
    }
    const double scale = area_uv > 0 && area_3d > 0 ? std::sqrt(area_3d / area_uv) : 0;
    for (auto& corners : flat.corner_uv)
      for (Point2& q : corners) q = {q[0] * scale, q[1] * scale};
    return flat;
  };

  // Every chart flattened, largest first, on up to hardware_concurrency threads (charts are
  // independent: the same UVs whatever the threads); report(fraction of the triangles) from the
  // calling thread.
  auto flatten_all = [&](const std::vector<uvgen::Chart>& charts, const std::function<void(double)>& report) {
    std::vector<uvgen::FlatChart> flat(charts.size());
    std::vector<size_t> order(charts.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return charts[a].triangles.size() > charts[b].triangles.size(); });
    std::atomic<size_t> next{0}, flattened{0};
    auto work = [&](bool reporting) {
      for (size_t i; (i = next.fetch_add(1)) < order.size();) {
        flat[order[i]] = flatten_scaled(charts[order[i]]);
        const size_t done = flattened.fetch_add(charts[order[i]].triangles.size()) + charts[order[i]].triangles.size();
        if (reporting) report(double(done) / double(std::max<size_t>(triangle_count, 1)));
      }
    };
    // Threads only where there is work to share: on a busy machine a helper thread can take longer
    // to start than a few thousand triangles take to flatten.
    size_t chart_triangles = 0;
    for (const uvgen::Chart& chart : charts) chart_triangles += chart.triangles.size();
    const size_t threads = chart_triangles < 20000 ? 1 : std::clamp<size_t>(std::thread::hardware_concurrency(), 1, charts.size());
    std::vector<std::thread> helpers;
    for (size_t t = 1; t < threads; ++t) helpers.emplace_back(work, false);
    work(true);
    for (std::thread& t : helpers) t.join();
    return flat;
  };

  // The charts' outlines for the packer. Degenerate faces: collapsed onto a chart's copy of one of
  // their vertices (no area, so they cover nothing of their own), or, when no chart has any of their
  // vertices, a point chart each (after the real charts).
  struct Outlines {
    std::vector<uvgen::ChartOutline> charts;
    std::vector<std::pair<int32_t, Point2>> collapsed;  // per degenerate triangle: chart, point
  };
  auto outline = [&](const std::vector<uvgen::Chart>& charts, const std::vector<uvgen::FlatChart>& flat) {
    Outlines o;
    std::vector<int32_t> vertex_chart(mesh.positions.size(), -1);
    std::vector<Point2> vertex_uv(mesh.positions.size());
    for (size_t c = 0; c < charts.size(); ++c)
      for (size_t i = 0; i < charts[c].triangles.size(); ++i)
        for (size_t k = 0; k < 3; ++k) {
          const uint32_t w = mesh.triangles[charts[c].triangles[i]][k];
          if (vertex_chart[w] < 0) vertex_chart[w] = int32_t(c), vertex_uv[w] = flat[c].corner_uv[i][k];
        }
    o.collapsed.assign(triangle_count, {-1, Point2{}});
    o.charts.resize(charts.size());
    for (uint32_t t = 0; t < triangle_count; ++t) {
      if (!mesh.degenerate[t]) continue;
      for (uint32_t w : mesh.triangles[t])
        if (vertex_chart[w] >= 0) {
          o.collapsed[t] = {vertex_chart[w], vertex_uv[w]};
          break;
        }
      if (o.collapsed[t].first < 0) {
        o.collapsed[t] = {int32_t(o.charts.size()), Point2{0, 0}};
        o.charts.push_back({{Point2{0, 0}, Point2{0, 0}, Point2{0, 0}}});
      }
    }
    for (size_t c = 0; c < charts.size(); ++c) {
      std::vector<Point2>& points = o.charts[c].points;
      for (const auto& corners : flat[c].corner_uv) points.insert(points.end(), corners.begin(), corners.end());
    }
    return o;
  };

  uvgen::PackingSettings packing;
  packing.texels_per_unit = settings.texels_per_unit;
  packing.max_side_texels = settings.max_side_texels;
  packing.gutter_texels = settings.gutter_texels;
  struct Layout {
    std::vector<uvgen::Chart> charts;
    std::vector<uvgen::FlatChart> flat;
    Outlines outlines;
    uvgen::PackedCharts packed;
  };
  // Progress: segmentation to 0.05, then flattening and packing the first layout to `first_end`,
  // then the layout search (if any) to 0.95, each step an equal share.
  const bool may_search = triangle_count <= settings.layout_search_max_triangles;
  const double first_end = may_search ? 0.5 : 0.95;
  const int search_steps = 6 + std::max(settings.split_charts, 0);
  int search_step = 0;
  auto search_progress = [&](double fraction) {
    progress.at(first_end + (0.95 - first_end) * (search_step + fraction) / search_steps);
  };
  // What a search layout must beat: a packing that fits the page and fills more of its rectangle.
  auto fill_to_beat = [](const uvgen::PackedCharts& best) {
    return best.fits ? best.texels_per_unit * best.texels_per_unit / (double(best.width) * best.height) : 0.0;
  };
  // Charts grown from `first_seed` (-1: the first face), flattened and packed; `report`: progress
  // over the first layout (flattening 0.05 to 60 % of the way to first_end, packing the rest), else
  // over one search step. `to_beat`: PackingSettings::fill_to_beat.
  auto lay_out = [&](int64_t first_seed, bool report, double to_beat) {
    Layout l;
    l.charts = uvgen::segment_into_charts(mesh, neighbour, segmentation, splitter, first_seed);
    if (report) progress.at(0.05);
    const double flattened_end = 0.05 + 0.6 * (first_end - 0.05);
    l.flat = flatten_all(l.charts, [&](double fraction) {
      if (report)
        progress.at(0.05 + (flattened_end - 0.05) * fraction);
      else
        search_progress(0.5 * fraction);
    });
    l.outlines = outline(l.charts, l.flat);
    uvgen::PackingSettings trial = packing;
    trial.fill_to_beat = to_beat;
    trial.progress = [&](double fraction) {
      if (report)
        progress.at(flattened_end + (first_end - flattened_end) * fraction);
      else
        search_progress(0.5 + 0.5 * fraction);
    };
    l.packed = uvgen::pack_charts(l.outlines.charts, trial);
    if (report) progress.at(first_end);
    return l;
  };
  Layout best = lay_out(-1, true, 0);

  // Two searches on small meshes (bench/results/uvgen.md), each layout kept only when its charts
  // fill more of the packed rectangle. First, where the first chart's cone boundaries fall decides
  // the charts' shapes: on a torus, arches across the tube or the tube's top and bottom halves; the
  // charts are also grown from the faces whose normals point farthest along each axis. A search
  // layout's packing is given up (beaten) once it cannot fill more than the best so far.
  auto fills_more = [](const uvgen::PackedCharts& a, const uvgen::PackedCharts& b) {
    if (a.beaten) return false;
    if (a.fits != b.fits) return a.fits;
    return a.texels_per_unit * a.texels_per_unit / (double(a.width) * a.height) >
           b.texels_per_unit * b.texels_per_unit / (double(b.width) * b.height);
  };
  // Planar charts (a building's boxes) flatten as they are, whichever face seeds them: only meshes
  // with a curved chart (a face over 10 degrees from its seed's normal) search.
  bool curved = false;
  for (const uvgen::Chart& chart : best.charts)
    for (uint32_t t : chart.triangles) {
      const uvgen::Point3& n = mesh.normals[t];
      curved = curved || n[0] * chart.normal[0] + n[1] * chart.normal[1] + n[2] * chart.normal[2] < kCurvedChartCos;
    }
  const bool search = curved && may_search;
  if (search)
    for (uint32_t seed : uvgen::axis_seed_faces(mesh)) {
      Layout trial = lay_out(int64_t(seed), false, fill_to_beat(best.packed));
      if (fills_more(trial.packed, best.packed)) best = std::move(trial);
      search_step = std::min(search_step + 1, 6);
    }
  search_step = 6;
  // Then arches (a torus's halves flatten to ~200-degree arches) fill little of their bounding box
  // and stack badly: the largest chart filling less than split_below_fill of its box is halved
  // across its long axis, up to split_charts times in a row; halving one arch of two does not pay,
  // halving both does (the halves stack), so the best layout of the sequence is kept.
  if (search) {
    Layout current = best;
    for (int split = 0; split < settings.split_charts; ++split) {
      int64_t pick = -1;
      double pick_area = 0;
      for (size_t c = 0; c < current.charts.size(); ++c) {
        if (current.charts[c].triangles.size() < 4) continue;
        double area = 0;
        for (uint32_t t : current.charts[c].triangles) area += mesh.areas[t];
        if (area > pick_area && uvgen::bounding_box_fill(current.outlines.charts[c]) < settings.split_below_fill)
          pick = int64_t(c), pick_area = area;
      }
      if (pick < 0) break;
      std::vector<uvgen::Chart> halves = uvgen::halve_chart(current.charts[size_t(pick)], current.flat[size_t(pick)], splitter);
      if (halves.size() < 2) break;
      Layout next;
      for (size_t c = 0; c < current.charts.size(); ++c) {
        if (c != size_t(pick)) {
          next.charts.push_back(std::move(current.charts[c])), next.flat.push_back(std::move(current.flat[c]));
          continue;
        }
        for (uvgen::Chart& half : halves) {
          next.flat.push_back(flatten_scaled(half));
          next.charts.push_back(std::move(half));
        }
      }
      next.outlines = outline(next.charts, next.flat);
      uvgen::PackingSettings trial = packing;
      trial.fill_to_beat = fill_to_beat(best.packed);
      trial.progress = search_progress;
      next.packed = uvgen::pack_charts(next.outlines.charts, trial);
      current = std::move(next);
      ++search_step;
      if (fills_more(current.packed, best.packed)) best = current;
    }
  }
  std::vector<uvgen::Chart>& charts = best.charts;
  std::vector<uvgen::FlatChart>& flat = best.flat;
  const Outlines& outlines = best.outlines;
  const uvgen::PackedCharts& packed = best.packed;
  progress.at(0.95);
  for (const uvgen::FlatChart& f : flat) (f.lscm ? stats.lscm_charts : stats.planar_charts)++;
  const size_t real_charts = charts.size();
  const auto& collapsed = outlines.collapsed;
  stats.degenerate_triangles = size_t(std::count(mesh.degenerate.begin(), mesh.degenerate.end(), uint8_t(1)));

  out.triangle_chart.assign(triangle_count, 0);
  out.corner_uv.assign(3 * triangle_count, Vec2{});
  auto store = [&](uint32_t t, size_t k, Point2 uv) {
    const float u = float(uv[0]), v = float(uv[1]);
    out.corner_uv[3 * t + k] = std::isfinite(u) && std::isfinite(v) ? Vec2{u, v} : Vec2{0, 0};
  };
  for (size_t c = 0; c < real_charts; ++c)
    for (size_t i = 0; i < charts[c].triangles.size(); ++i) {
      const uint32_t t = charts[c].triangles[i];
      out.triangle_chart[t] = uint32_t(c);
      for (size_t k = 0; k < 3; ++k) store(t, k, packed.uv(c, flat[c].corner_uv[i][k]));
    }
  for (uint32_t t = 0; t < triangle_count; ++t)
    if (mesh.degenerate[t]) {
      out.triangle_chart[t] = uint32_t(collapsed[t].first);
      for (size_t k = 0; k < 3; ++k) store(t, k, packed.uv(size_t(collapsed[t].first), collapsed[t].second));
    }

  // Statistics on the UVs as stored (floats), normalized so UV area equals 3-D area over the mesh.
  stats.charts = outlines.charts.size();
  stats.packed_width = packed.width;
  stats.packed_height = packed.height;
  stats.texels_per_unit = packed.texels_per_unit;
  stats.gutter_holds = packed.fits;
  double total_3d = 0, total_uv = 0;
  auto stored = [&](uint32_t t) {
    std::array<Point2, 3> uv;
    for (size_t k = 0; k < 3; ++k) uv[k] = {out.corner_uv[3 * t + k].x, out.corner_uv[3 * t + k].y};
    return uv;
  };
  for (uint32_t t = 0; t < triangle_count; ++t) {
    total_3d += mesh.areas[t];
    total_uv += uv_area(stored(t));
  }
  const double side = double(std::max(packed.width, packed.height));
  stats.utilization = total_uv * side * side / (double(packed.width) * packed.height);
  const double uv_to_3d = total_uv > 0 ? std::sqrt(total_3d / total_uv) : 1;
  double area_sum = 0, angle_sum = 0, weight_sum = 0;
  stats.max_area_distortion = stats.max_angle_distortion = 1;
  for (size_t c = 0; c < real_charts; ++c) {
    double chart_area = 0, chart_angle = 0, chart_weight = 0;
    for (uint32_t t : charts[c].triangles) {
      std::array<Point3, 3> p;
      for (size_t k = 0; k < 3; ++k) p[k] = mesh.positions[mesh.triangles[t][k]];
      const uvgen::TriangleDistortion d = uvgen::triangle_distortion(p, stored(t), uv_to_3d);
      const double w = mesh.areas[t];
      stats.max_area_distortion = std::max(stats.max_area_distortion, d.area);
      stats.max_angle_distortion = std::max(stats.max_angle_distortion, d.angle);
      chart_area += w * d.area, chart_angle += w * d.angle, chart_weight += w;
    }
    area_sum += chart_area, angle_sum += chart_angle, weight_sum += chart_weight;
    if (chart_weight > 0 &&
        (chart_area / chart_weight > settings.stretch_bound || chart_angle / chart_weight > settings.stretch_bound))
      ++stats.stretched_charts;
  }
  if (weight_sum > 0) {
    stats.mean_area_distortion = area_sum / weight_sum;
    stats.mean_angle_distortion = angle_sum / weight_sum;
  }
  progress.at(1);
  return out;
}

}  // namespace exitance
