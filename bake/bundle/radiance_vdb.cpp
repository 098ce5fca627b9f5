// SVO leaves → OpenVDB grids (radiance.vdb); see radiance_vdb.h for the grids and the transform.
#include "exitance/bake/bundle/radiance_vdb.h"

#include <openvdb/openvdb.h>

#include <bit>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace exitance {
namespace {

void initialize_openvdb_once() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// Integer cell coordinates of every node at its own level, top-down: a child's cell is twice its
// parent's plus its octant bits (bit 0 = x, bit 1 = y, bit 2 = z).
std::vector<openvdb::Coord> node_cells(const formats::SparseVoxelOctree& svo) {
  std::vector<openvdb::Coord> cells(svo.nodes.size(), openvdb::Coord(0, 0, 0));
  for (size_t i = 0; i < svo.nodes.size(); ++i) {
    const formats::SvoNode& node = svo.nodes[i];
    uint32_t child = node.first_child;
    for (uint32_t octant = 0; octant < 8; ++octant) {
      if (!(node.child_mask & (1u << octant))) continue;
      cells[child] = openvdb::Coord(2 * cells[i].x() + int(octant & 1u), 2 * cells[i].y() + int((octant >> 1) & 1u),
                                    2 * cells[i].z() + int((octant >> 2) & 1u));
      ++child;
    }
  }
  return cells;
}

template <typename GridType>
typename GridType::Ptr make_grid(const char* name, const openvdb::math::Transform::Ptr& transform,
                                 const char* units) {
  typename GridType::Ptr grid = GridType::create();
  grid->setName(name);
  grid->setTransform(transform);
  grid->insertMeta("units", openvdb::StringMetadata(units));
  return grid;
}

openvdb::Vec3SGrid::Ptr make_exitance_grid(const char* name, const openvdb::math::Transform::Ptr& transform,
                                           const char* side) {
  openvdb::Vec3SGrid::Ptr grid = make_grid<openvdb::Vec3SGrid>(name, transform, "W/m^2 radiant exitance");
  grid->insertMeta("definition", openvdb::StringMetadata("exitance = pi * outgoing radiance"));
  grid->insertMeta("side", openvdb::StringMetadata(side));
  return grid;
}

}  // namespace

void write_radiance_vdb(const std::string& path, const formats::SparseVoxelOctree& svo) {
  initialize_openvdb_once();
  try {
    // Leaf (i, j, k) has its centre at origin + (ijk + 0.5) * leaf; OpenVDB puts index points at
    // voxel centres, so scale by the leaf size and shift by origin + half a leaf.
    const double leaf = svo.size > 0 ? double(svo.voxel_size(svo.depth)) : 1.0;
    openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(leaf);
    transform->postTranslate(openvdb::Vec3d(double(svo.origin[0]) + 0.5 * leaf, double(svo.origin[1]) + 0.5 * leaf,
                                            double(svo.origin[2]) + 0.5 * leaf));

    openvdb::FloatGrid::Ptr occupancy = make_grid<openvdb::FloatGrid>("occupancy", transform, "1 = occupied leaf voxel");
    occupancy->setGridClass(openvdb::GRID_FOG_VOLUME);
    openvdb::Vec3SGrid::Ptr front = make_exitance_grid("exitance_front", transform, "the side the voxel normal points to");
    openvdb::Vec3SGrid::Ptr back = make_exitance_grid("exitance_back", transform, "the side opposite the voxel normal");
    openvdb::Vec3SGrid::Ptr normal = make_grid<openvdb::Vec3SGrid>("normal", transform, "unit vector");
    normal->setVectorType(openvdb::VEC_COVARIANT_NORMALIZE);

    if (!svo.nodes.empty() && svo.level_begin.size() == svo.depth + 2) {
      const std::vector<openvdb::Coord> cells = node_cells(svo);
      openvdb::FloatGrid::Accessor occupied = occupancy->getAccessor();
      openvdb::Vec3SGrid::Accessor front_value = front->getAccessor(), back_value = back->getAccessor(),
                                   normal_value = normal->getAccessor();
      for (uint32_t i = svo.level_begin[svo.depth]; i < svo.level_begin[svo.depth + 1]; ++i) {
        const openvdb::Coord& ijk = cells[i];
        occupied.setValue(ijk, 1.0f);
        const std::array<float, 3> f = formats::svo_node_exitance(svo, i, 0), b = formats::svo_node_exitance(svo, i, 1);
        const std::array<float, 3> n = formats::decode_octahedral_normal(svo.nodes[i].normal_oct);
        front_value.setValue(ijk, openvdb::Vec3s(f[0], f[1], f[2]));
        back_value.setValue(ijk, openvdb::Vec3s(b[0], b[1], b[2]));
        normal_value.setValue(ijk, openvdb::Vec3s(n[0], n[1], n[2]));
      }
    }

    openvdb::GridPtrVec grids{occupancy, front, back, normal};
    openvdb::io::File file(path);
    file.write(grids);
    file.close();
  } catch (const openvdb::Exception& e) {
    throw std::runtime_error(path + ": cannot write OpenVDB file: " + e.what());
  }
}

}  // namespace exitance
