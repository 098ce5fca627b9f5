// Small bundles built by hand for the loader tests and the sample/install tests, with closed-form
// content: a page whose texels are a bilinear polynomial of the texel index, a probe grid whose
// SH coefficients are affine in the probe position, and a depth-2 octree with known nodes.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/formats/probe_grid.h"
#include "exitance/formats/sparse_voxel_octree.h"

namespace exitance::test {

// Page 0 (8 x 4): channel c of texel (x, y) is page0_value(c, x, y). A polynomial in x, y with an
// x*y term: bilinear interpolation reproduces it exactly between texel centres.
constexpr int kPage0Width = 8, kPage0Height = 4;
double page0_value(int channel, double x, double y);
// Page 1 (4 x 4): constant kPage1Value in R, G, B.
constexpr float kPage1Value = 0.25f;
formats::LightmapImage make_page0();
formats::LightmapImage make_page1();
// Instance 0 maps TEXCOORD_1 onto page 0 by kInstance0ScaleOffset; instance 1 covers page 1.
constexpr std::array<float, 4> kInstance0ScaleOffset{0.5f, 0.5f, 0.25f, 0.5f};

// Probe grid: origin (-1, 0, 2), spacing (0.5, 1, 2), counts 3 x 2 x 2; coefficient k, channel c
// of the probe at grid point p is linear_probe_field(k, c, p).
double linear_probe_field(int coefficient, int channel, const std::array<double, 3>& p);
formats::ProbeGrid make_linear_probe_grid();

// Octree over the cube [0, 8]^3, depth 2, exitance_scale 2:
//   node 0 root, children in octants 0 and 7 -> nodes 1, 2
//   node 1 = [0,4]^3, children octants 1, 2 -> nodes 3 ([2,4]x[0,2]x[0,2]), 4 ([0,2]x[2,4]x[0,2])
//   node 2 = [4,8]^3, child octant 7 -> node 5 ([6,8]^3)
// Node i: normal +Y (node 5: +X); front exitance svo_front(i), back svo_back(i) (before the scale).
formats::SparseVoxelOctree make_test_octree();
std::array<float, 3> svo_front(int node);
std::array<float, 3> svo_back(int node);
constexpr float kSvoExitanceScale = 2.0f;

// Writes manifest.json (the given text; test_manifest.h makes one), lightmap-0.exr,
// lightmap-1.exr and, when given, probes.bin and svo.bin.
void write_bundle(const std::string& directory, const std::string& manifest_text,
                  const std::optional<formats::ProbeGrid>& probes, const std::optional<formats::SparseVoxelOctree>& svo);

// A fresh empty folder under the system temp folder, unique per process and name.
std::string fresh_directory(const std::string& name);

}  // namespace exitance::test
