// write_fuzz_seeds DIR: valid probes.bin, svo.bin, scene.bin, manifest.json and EDITS.json files, written by
// the real writers, as the fuzzers' starting corpus (DIR/probes, DIR/svo, DIR/scene, DIR/manifest).
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "exitance/formats/probes_file.h"
#include "exitance/formats/scene_file.h"
#include "exitance/formats/svo_file.h"
#include "sample_scene_file.h"

using namespace exitance::formats;
namespace fs = std::filesystem;

namespace {

ProbeGrid probe_grid(std::array<uint32_t, 3> counts) {
  ProbeGrid grid;
  grid.origin = {-1, 0, 2};
  grid.spacing = {0.5f, 1, 2};
  grid.counts = counts;
  grid.probes.resize(size_t(counts[0]) * counts[1] * counts[2]);
  for (size_t i = 0; i < grid.probes.size(); ++i) {
    ProbeRecord& p = grid.probes[i];
    p.position = {float(i), 1, 2};
    p.state = ProbeState(i % 4);
    if (probe_is_usable(p))
      for (size_t k = 0; k < p.sh.size(); ++k) p.sh[k] = float(k) * 0.1f - float(i);
  }
  return grid;
}

// A full octree of the given depth along one diagonal: one node per level, octant 0 or 7.
SparseVoxelOctree chain_octree(uint32_t depth) {
  SparseVoxelOctree svo;
  svo.origin = {-4, -4, -4};
  svo.size = 8;
  svo.depth = depth;
  svo.exitance_scale = 0.5f;
  for (uint32_t level = 0; level <= depth; ++level) {
    SvoNode n;
    n.level = uint8_t(level);
    n.parent = level == 0 ? kSvoNoParent : level - 1;
    n.child_mask = level < depth ? uint8_t(level % 2 ? 0x80 : 0x01) : 0;
    n.first_child = level < depth ? level + 1 : 0;
    n.flags = uint16_t(kSvoFrontLit | (level == depth ? kSvoLeaf : 0));
    n.normal_oct = encode_octahedral_normal({0, 1, 0});
    for (int c = 0; c < 6; ++c) n.exitance[c] = float_to_half(float(level + c));
    svo.nodes.push_back(n);
  }
  for (uint32_t level = 0; level <= depth + 1; ++level) svo.level_begin.push_back(level);
  return svo;
}

// Depth 1: a root with three children (octants 0, 3, 6).
SparseVoxelOctree bushy_octree() {
  SparseVoxelOctree svo;
  svo.size = 2;
  svo.depth = 1;
  svo.level_begin = {0, 1, 4};
  SvoNode root;
  root.child_mask = 0b01001001;
  root.first_child = 1;
  root.flags = kSvoFrontLit | kSvoBackLit;
  svo.nodes.push_back(root);
  for (int i = 0; i < 3; ++i) {
    SvoNode leaf;
    leaf.parent = 0;
    leaf.level = 1;
    leaf.flags = kSvoLeaf | kSvoBackFilled;
    leaf.normal_oct = encode_octahedral_normal({float(i) - 1, 0.5f, -1});
    leaf.exitance[3] = float_to_half(3.5f);
    svo.nodes.push_back(leaf);
  }
  return svo;
}

void write_text(const fs::path& path, const char* text) { std::ofstream(path) << text; }

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
    return 2;
  }
  const fs::path dir = argv[1];
  for (const char* kind : {"probes", "svo", "scene", "manifest", "edits"}) fs::create_directories(dir / kind);
  write_probes_file((dir / "probes" / "grid-2x2x2.bin").string(), probe_grid({2, 2, 2}));
  write_probes_file((dir / "probes" / "grid-3x1x1.bin").string(), probe_grid({3, 1, 1}));
  write_probes_file((dir / "probes" / "grid-1x1x1.bin").string(), probe_grid({1, 1, 1}));
  SparseVoxelOctree empty;
  empty.level_begin = {0, 0};
  write_svo_file((dir / "svo" / "empty.bin").string(), empty);
  write_svo_file((dir / "svo" / "chain-0.bin").string(), chain_octree(0));
  write_svo_file((dir / "svo" / "chain-3.bin").string(), chain_octree(3));
  write_svo_file((dir / "svo" / "bushy.bin").string(), bushy_octree());
  // scene.bin: the tests' sample (every section used), without probes, and empty.
  SceneFile scene = exitance::test::make_sample_scene_file();
  write_scene_file((dir / "scene" / "sample.bin").string(), scene);
  scene.probes = SceneFile::no_probe_grid();
  scene.texels.moved.clear();
  write_scene_file((dir / "scene" / "no-probes.bin").string(), scene);
  // Version 2's sections (textures, bindings, alpha modes, vertex colours, environment sky), and the
  // same sample in the version 1 layout.
  write_scene_file((dir / "scene" / "textured.bin").string(), exitance::test::make_textured_sample_scene_file());
  // Version 3's normal texture bindings and tangent frames.
  write_scene_file((dir / "scene" / "normal-mapped.bin").string(), exitance::test::make_normal_mapped_sample_scene_file());
  const std::vector<uint8_t> version2 = encode_scene(exitance::test::make_textured_sample_scene_file(), 2);
  std::ofstream((dir / "scene" / "version2.bin").string(), std::ios::binary)
      .write(reinterpret_cast<const char*>(version2.data()), std::streamsize(version2.size()));
  const std::vector<uint8_t> version1 = encode_scene(exitance::test::make_sample_scene_file(), 1);
  std::ofstream((dir / "scene" / "version1.bin").string(), std::ios::binary)
      .write(reinterpret_cast<const char*>(version1.data()), std::streamsize(version1.size()));
  SceneFile empty_scene;
  empty_scene.bvh.nodes.resize(1);
  exitance::test::set_empty_children(empty_scene.bvh.nodes[0]);
  write_scene_file((dir / "scene" / "empty.bin").string(), empty_scene);
  write_text(dir / "manifest" / "full.json", R"({"format_version": 1, "generator": "exitance 0.1.0",
 "input": {"file": "scene.gltf", "sha256": "0000000000000000000000000000000000000000000000000000000000000000"},
 "units": {"lightmap": "irradiance_over_pi", "probes": "incident_radiance_sh_l2", "length": "scene"},
 "pages": [{"file": "lightmap-0.exr", "width": 1024, "height": 1024, "channels": ["R", "G", "B", "A"]}],
 "instances": [{"node": 0, "name": "Floor", "mesh": 0, "page": 0, "scale_offset": [0.25, 0.25, 0.0, 0.5], "rect": [0, 0, 4, 4]}],
 "probes": {"file": "probes.bin", "origin": [0, 0, 0], "spacing": [1, 1, 1], "counts": [8, 4, 8], "sh_order": 2},
 "svo": {"file": "svo.bin", "bounds": [[0, 0, 0], [8, 8, 8]], "depth": 8},
 "light_layers": {"count": 5, "punctual": 2, "files": ["light-layers-0.exr"], "units": "irradiance_over_pi"},
 "stats": {"seconds": {"import": 0.1}, "rays": 0}})");
  write_text(dir / "manifest" / "minimal.json", R"({"format_version": 1, "pages": [], "instances": []})");
  // EDITS.json on the sample scene's names (docs/edits.md): every kind of edit.
  write_text(dir / "edits" / "all.json", R"({"edits": [{"node": "root", "translation": [1, 2, 3], "rotation": [0, 0, 0, 1]},
 {"node": "Wall", "scale": [1, 2, 1]}, {"node": 1, "translation": [0, 0.5, 0]},
 {"light": "Sun", "intensity": 2.5, "color": [1, 0.5, 0.25]}, {"material": 1, "emissiveStrength": 3, "emissiveFactor": [1, 1, 0]},
 {"sky": [0.1, 0.2, 0.3]}]})");
  write_text(dir / "edits" / "none.json", R"({"edits": []})");
  return 0;
}
