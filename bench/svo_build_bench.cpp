// SVO build time per phase on one scene: imports a glTF, builds the octree --repeat times at
// --voxel-resolution, prints the median seconds of each phase and the octree's size.
//
//   bench_svo_build SCENE.gltf [--voxel-resolution 256] [--repeat 5] [--vdb FILE]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <thread>
#include <vector>

#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/bundle/radiance_vdb.h"
#include "exitance/bake/voxelize/svo_build.h"

#include "wall_clock.h"

using namespace exitance;
using exitance::bench::median;
using exitance::bench::seconds_since;

int main(int argc, char** argv) {
  std::string scene_path, vdb_path;
  uint32_t resolution = 256, repeat = 5;
  CLI::App app{"sparse voxel octree build time"};
  app.add_option("scene", scene_path)->required();
  app.add_option("--voxel-resolution", resolution, "leaves per axis (power of two, 2..4096)");
  app.add_option("--repeat", repeat, "builds to take the median of")->check(CLI::PositiveNumber);
  app.add_option("--vdb", vdb_path, "also write the last octree as radiance.vdb to this file");
  CLI11_PARSE(app, argc, argv);

  try {
    Diagnostics diagnostics;
    const Scene scene = import_gltf(scene_path, ImportOptions{}, diagnostics);
    const SvoBuildSettings settings{svo_depth_from_resolution(resolution)};
    std::vector<SvoBuildStatistics> runs;
    formats::SparseVoxelOctree svo;
    for (uint32_t i = 0; i < repeat; ++i) {
      SvoBuildStatistics stats;
      svo = build_sparse_voxel_octree(scene, settings, &stats);
      runs.push_back(stats);
    }
    auto median_of = [&](double SvoBuildStatistics::*field) {
      std::vector<double> values;
      for (const SvoBuildStatistics& run : runs) values.push_back(run.*field);
      return median(values);
    };
    const SvoBuildStatistics& last = runs.back();
    std::printf("scene %s: %zu triangles (%llu voxelized), %u hardware threads\n", scene_path.c_str(),
                scene.triangle_count(), (unsigned long long)last.triangles_voxelized, std::thread::hardware_concurrency());
    std::printf("resolution %u^3 (depth %u), cube %.4g, leaf %.4g; median of %u builds:\n", resolution, settings.depth,
                double(svo.size), double(svo.voxel_size(svo.depth)), repeat);
    std::printf("  bounds     %8.4f s\n", median_of(&SvoBuildStatistics::bounds_seconds));
    std::printf("  voxelize   %8.4f s\n", median_of(&SvoBuildStatistics::voxelize_seconds));
    std::printf("  sort       %8.4f s\n", median_of(&SvoBuildStatistics::sort_seconds));
    std::printf("  leaves     %8.4f s\n", median_of(&SvoBuildStatistics::leaves_seconds));
    std::printf("  hierarchy  %8.4f s\n", median_of(&SvoBuildStatistics::hierarchy_seconds));
    std::printf("  total      %8.4f s\n", median_of(&SvoBuildStatistics::total_seconds));
    std::printf("triangle/voxel pairs %llu, leaves %llu, nodes %llu, %.1f bytes per node, %llu bytes in all (%.2f MiB)\n",
                (unsigned long long)last.triangle_voxel_pairs, (unsigned long long)last.leaves,
                (unsigned long long)last.nodes, last.bytes_per_node, (unsigned long long)last.total_bytes,
                double(last.total_bytes) / (1024.0 * 1024.0));
    if (!vdb_path.empty()) {
      write_radiance_vdb(vdb_path, svo);
      std::printf("wrote %s\n", vdb_path.c_str());
    }
  } catch (const std::exception& e) {
    std::cerr << "bench_svo_build: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
