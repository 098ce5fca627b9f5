// A baked bundle (scene.bake/: manifest.json, lightmap-N.exr, probes.bin, svo.bin) loaded for an
// engine: the atlas pages and per-instance scale/offset, and lookups of lightmap E/pi, probe SH
// and SVO exitance. Everything is read and validated in open(); a Bundle is immutable after it,
// so lookups may run from any number of threads.
//
//   auto bundle = exitance::loader::Bundle::open("scene.bake");
//   exitance::loader::Rgb e_over_pi = bundle.lightmap(0, {0.5f, 0.5f});
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "exitance/formats/format_error.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/formats/probe_grid.h"
#include "exitance/formats/sparse_voxel_octree.h"
#include "exitance/loader/lookup_results.h"
#include "exitance/loader/manifest.h"

namespace exitance::loader {

class Bundle {
 public:
  // Throws formats::FormatError (formats::FileAccessError for a missing or unreadable file) with a
  // one-line message naming the file, the element and the problem. Cross-checks the manifest
  // against the files: page sizes and channels, probe grid (origin, spacing, counts, SH order),
  // SVO (bounds, depth).
  static Bundle open(const std::string& directory);

  const std::string& directory() const { return directory_; }
  const Manifest& manifest() const { return manifest_; }
  const std::vector<PageInfo>& pages() const { return manifest_.pages; }
  const std::vector<InstanceInfo>& instances() const { return manifest_.instances; }
  const formats::LightmapImage& page_image(size_t page) const;  // every channel of the EXR

  // E/pi (RGB) at an instance's lightmap UV (TEXCOORD_1), bilinear at page UV uv * s + o with
  // clamp to edge. Throws std::out_of_range for a bad instance, std::invalid_argument for a
  // non-finite uv.
  Rgb lightmap(size_t instance, std::array<float, 2> uv) const;
  // The same lookup of one other channel of the instance's page (e.g. "error.Y"). Throws
  // std::out_of_range when that page lacks the channel (has_lightmap_channel says beforehand).
  float lightmap_channel(size_t instance, const std::string& channel, std::array<float, 2> uv) const;
  // True when every page holds the channel.
  bool has_lightmap_channel(const std::string& channel) const;

  bool has_probes() const { return probes_.has_value(); }
  const formats::ProbeGrid* probe_grid() const { return probes_ ? &*probes_ : nullptr; }
  // Trilinear SH of incident radiance, unusable probes weighted out. Throws std::logic_error when
  // the bundle has no probes, std::invalid_argument for a non-finite point.
  ProbeShResult probe_sh(Point3 point) const;
  // E(n)/pi from the interpolated SH; also throws std::invalid_argument for a zero or non-finite normal.
  ProbeIrradianceResult probe_irradiance_over_pi(Point3 point, Point3 normal) const;

  bool has_svo() const { return svo_.has_value(); }
  const formats::SparseVoxelOctree* octree() const { return svo_ ? &*svo_ : nullptr; }
  // Exitance of the node containing the point at `level` (or the deepest existing node above it),
  // side chosen by the normal. Throws std::logic_error without an SVO, std::invalid_argument for
  // a non-finite point or a zero or non-finite normal.
  SvoExitanceResult svo_exitance(Point3 point, uint32_t level, Point3 normal) const;

 private:
  Bundle() = default;
  std::string directory_;
  Manifest manifest_;
  std::vector<formats::LightmapImage> page_images_;
  std::optional<formats::ProbeGrid> probes_;
  std::optional<formats::SparseVoxelOctree> svo_;
};

}  // namespace exitance::loader
