// radiance.vdb: a known octree written, then inspected with OpenVDB's own vdb_print (grids, voxel
// counts, bounding box, metadata) and read back with OpenVDB (transform, values).
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <unistd.h>

#include "exitance/bake/bundle/radiance_vdb.h"
#include "exitance/bake/voxelize/svo_build.h"
#include "exitance/formats/half_float.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

// 2.9 × 1.13 in the plane z = 5.3 at depth 5: leaves of 0.1, cells x 1..30, y 10..21, z 16
// (svo_build_test checks this leaf set against brute force).
formats::SparseVoxelOctree known_octree() {
  Scene scene;
  scene.materials.push_back(Material{});
  const Vec3 a{3.7f, -2.1f, 5.3f}, b{6.6f, -2.1f, 5.3f}, c{6.6f, -0.97f, 5.3f}, d{3.7f, -0.97f, 5.3f};
  for (Vec3 p : {a, b, c, a, c, d}) scene.positions.push_back(p), scene.normals.push_back({0, 0, 1});
  scene.triangle_material = {0, 0};
  scene.triangle_instance = {0, 0};
  return build_sparse_voxel_octree(scene, {5});
}

std::array<float, 3> leaf_centre(const formats::SparseVoxelOctree& svo, int i, int j, int k) {
  const float leaf = svo.voxel_size(svo.depth);
  return {svo.origin[0] + (float(i) + 0.5f) * leaf, svo.origin[1] + (float(j) + 0.5f) * leaf,
          svo.origin[2] + (float(k) + 0.5f) * leaf};
}

fs::path temporary_file(const std::string& name) {
  return fs::temp_directory_path() / (name + "-" + std::to_string(::getpid()) + ".vdb");
}

std::string run(const std::string& command) {
  std::string output;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run " + command);
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) output.append(buffer, n);
  EXPECT_EQ(::pclose(pipe), 0) << command;
  return output;
}

// vdb_print -l's report, one section per grid, keyed by grid name.
std::map<std::string, std::string> grid_sections(const std::string& report) {
  std::map<std::string, std::string> sections;
  size_t at = report.find("Name: ");
  while (at != std::string::npos) {
    const size_t next = report.find("Name: ", at + 1);
    const size_t name_end = report.find('\n', at);
    sections[report.substr(at + 6, name_end - at - 6)] = report.substr(at, next - at);
    at = next;
  }
  return sections;
}

TEST(RadianceVdb, VdbPrintSeesTheGridsVoxelsAndMetadata) {
#ifndef EXITANCE_VDB_PRINT
  GTEST_SKIP() << "vdb_print (libopenvdb-tools) was not found at configure time";
#else
  formats::SparseVoxelOctree svo = known_octree();
  const fs::path path = temporary_file("radiance_vdb_print");
  write_radiance_vdb(path.string(), svo);
  const std::map<std::string, std::string> grids = grid_sections(run(std::string(EXITANCE_VDB_PRINT) + " -l " + path.string()));
  fs::remove(path);
  ASSERT_EQ(grids.size(), 4u);
  for (const char* name : {"occupancy", "exitance_front", "exitance_back", "normal"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(grids.count(name));
    const std::string& section = grids.at(name);
    EXPECT_NE(section.find("Number of active voxels:       360\n"), std::string::npos) << section;
    EXPECT_NE(section.find("Bounding box of active voxels: [1, 10, 16] -> [30, 21, 16]"), std::string::npos) << section;
    EXPECT_NE(section.find("voxel size: 0.1\n"), std::string::npos) << section;
  }
  EXPECT_NE(grids.at("occupancy").find("Type: Tree_float_5_4_3"), std::string::npos);
  for (const char* name : {"exitance_front", "exitance_back"}) {
    EXPECT_NE(grids.at(name).find("Type: Tree_vec3s_5_4_3"), std::string::npos);
    EXPECT_NE(grids.at(name).find("units: W/m^2 radiant exitance"), std::string::npos);
    EXPECT_NE(grids.at(name).find("definition: exitance = pi * outgoing radiance"), std::string::npos);
  }
#endif
}

TEST(RadianceVdb, TransformAndValuesReadBack) {
  formats::SparseVoxelOctree svo = known_octree();
  // Exitance on two leaves, through the half encoding and its scale.
  svo.exitance_scale = 4.0f;
  const uint32_t corner = formats::svo_find_node(svo, leaf_centre(svo, 1, 10, 16), svo.depth);
  const uint32_t far = formats::svo_find_node(svo, leaf_centre(svo, 30, 21, 16), svo.depth);
  ASSERT_EQ(svo.nodes[corner].level, svo.depth);
  ASSERT_EQ(svo.nodes[far].level, svo.depth);
  const float front[3] = {0.5f, 1.25f, 2.0f}, back[3] = {0.125f, 0, 3.5f};
  for (int c = 0; c < 3; ++c) {
    svo.nodes[corner].exitance[c] = formats::float_to_half(front[c] / svo.exitance_scale);
    svo.nodes[far].exitance[3 + c] = formats::float_to_half(back[c] / svo.exitance_scale);
  }
  const fs::path path = temporary_file("radiance_vdb_read");
  write_radiance_vdb(path.string(), svo);

  openvdb::initialize();
  openvdb::io::File file(path.string());
  file.open();
  const openvdb::FloatGrid::Ptr occupancy = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("occupancy"));
  const openvdb::Vec3SGrid::Ptr front_grid = openvdb::gridPtrCast<openvdb::Vec3SGrid>(file.readGrid("exitance_front"));
  const openvdb::Vec3SGrid::Ptr back_grid = openvdb::gridPtrCast<openvdb::Vec3SGrid>(file.readGrid("exitance_back"));
  const openvdb::Vec3SGrid::Ptr normal_grid = openvdb::gridPtrCast<openvdb::Vec3SGrid>(file.readGrid("normal"));
  file.close();
  fs::remove(path);
  ASSERT_TRUE(occupancy && front_grid && back_grid && normal_grid);
  EXPECT_EQ(occupancy->getGridClass(), openvdb::GRID_FOG_VOLUME);
  EXPECT_EQ(occupancy->activeVoxelCount(), 360u);

  // Index (1, 10, 16) is the leaf whose centre is origin + (1.5, 10.5, 16.5) * leaf.
  const openvdb::Vec3d world = occupancy->indexToWorld(openvdb::Coord(1, 10, 16));
  const std::array<float, 3> centre = leaf_centre(svo, 1, 10, 16);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(world[k], centre[size_t(k)], 1e-5);
  // The quad's corner (3.7, -2.1, 5.3) lies in that leaf, and the whole quad in active voxels.
  const openvdb::Coord corner_voxel = occupancy->transform().worldToIndexCellCentered(openvdb::Vec3d(3.7, -2.1, 5.3));
  EXPECT_EQ(corner_voxel, openvdb::Coord(1, 10, 16));
  EXPECT_EQ(occupancy->tree().getValue(corner_voxel), 1.0f);
  EXPECT_TRUE(occupancy->tree().isValueOn(occupancy->transform().worldToIndexCellCentered(openvdb::Vec3d(6.59, -0.98, 5.3))));
  EXPECT_FALSE(occupancy->tree().isValueOn(occupancy->transform().worldToIndexCellCentered(openvdb::Vec3d(3.7, -2.1, 5.5))));

  const openvdb::Vec3s front_value = front_grid->tree().getValue(openvdb::Coord(1, 10, 16));
  const openvdb::Vec3s back_value = back_grid->tree().getValue(openvdb::Coord(30, 21, 16));
  for (int c = 0; c < 3; ++c) {
    EXPECT_FLOAT_EQ(front_value[c], front[c]);
    EXPECT_FLOAT_EQ(back_value[c], back[c]);
  }
  EXPECT_EQ(back_grid->tree().getValue(openvdb::Coord(1, 10, 16)), openvdb::Vec3s(0, 0, 0));
  EXPECT_NEAR(normal_grid->tree().getValue(openvdb::Coord(5, 15, 16))[2], 1.0f, 1e-4f);
  EXPECT_EQ(front_grid->metaValue<std::string>("units"), "W/m^2 radiant exitance");
}

TEST(RadianceVdb, EmptyOctreeAndUnwritablePath) {
  const fs::path path = temporary_file("radiance_vdb_empty");
  write_radiance_vdb(path.string(), build_sparse_voxel_octree(Scene{}, {4}));
  openvdb::initialize();
  openvdb::io::File file(path.string());
  file.open();
  EXPECT_EQ(file.readGrid("occupancy")->activeVoxelCount(), 0u);
  file.close();
  fs::remove(path);

  const std::string bad = "/nonexistent-exitance-dir/radiance.vdb";
  try {
    write_radiance_vdb(bad, known_octree());
    FAIL() << "no error for an unwritable path";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace exitance
