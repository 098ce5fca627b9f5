#include "exitance/loader/bundle.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <new>
#include <sstream>
#include <stdexcept>

#include "exitance/formats/probes_file.h"
#include "exitance/formats/svo_file.h"
#include "lightmap_lookup.h"
#include "probe_lookup.h"
#include "svo_lookup.h"

namespace exitance::loader {
namespace fs = std::filesystem;
using formats::FileAccessError;
using formats::FormatError;

namespace {

std::string read_text_file(const fs::path& path) {
  std::error_code error;
  if (!fs::is_regular_file(path, error))
    throw FileAccessError(path.string() + ": cannot open: " + (fs::exists(path, error) ? "not a regular file" : "no such file"));
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  if (!file) throw FileAccessError(path.string() + ": cannot read");
  return text.str();
}

// A bundle file named by the manifest must exist before a reader is pointed at it, so a missing
// file is reported as such (FileAccessError) rather than as whatever the reader makes of it.
fs::path existing_bundle_file(const fs::path& directory, const std::string& file, const std::string& manifest_field) {
  const fs::path path = directory / file;
  std::error_code error;
  if (!fs::is_regular_file(path, error))
    throw FileAccessError(path.string() + ": missing (named by manifest.json " + manifest_field + ")");
  return path;
}

// Manifest floats are written from the same float values the binary headers hold, but a baker
// may compute the cube's far corner in another precision: allow a few ulps of the magnitude.
bool nearly_equal(float manifest_value, float file_value, float magnitude) {
  return std::fabs(manifest_value - file_value) <= 1e-5f * std::max({1.0f, std::fabs(file_value), magnitude});
}

void require_finite(const Point3& v, const char* what) {
  if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])))
    throw std::invalid_argument(std::string(what) + " is not finite");
}

void require_direction(const Point3& v, const char* what) {
  require_finite(v, what);
  if (v[0] == 0 && v[1] == 0 && v[2] == 0) throw std::invalid_argument(std::string(what) + " is zero");
}

formats::LightmapImage load_page(const fs::path& directory, const PageInfo& page, size_t index) {
  const std::string field = "pages[" + std::to_string(index) + "]";
  const fs::path path = existing_bundle_file(directory, page.file, field);
  formats::LightmapImage image;
  try {
    image = formats::read_lightmap_exr(path.string());
  } catch (const std::bad_alloc&) {
    throw;  // out of memory stays out of memory (the C API reports it apart)
  } catch (const std::exception& e) {  // OpenEXR's own messages, already naming the file
    throw FormatError(e.what());
  }
  if (image.width != int(page.width) || image.height != int(page.height))
    throw FormatError(path.string() + ": " + std::to_string(image.width) + " x " + std::to_string(image.height) +
                      " texels, manifest.json " + field + " says " + std::to_string(page.width) + " x " +
                      std::to_string(page.height));
  const size_t texels = size_t(page.width) * page.height;
  for (const char* channel : {"R", "G", "B"}) {
    const auto it = image.channels.find(channel);
    if (it == image.channels.end()) throw FormatError(path.string() + ": channel " + channel + " missing (E/pi needs R, G, B)");
    if (it->second.size() != texels) throw FormatError(path.string() + ": channel " + channel + " has the wrong size");
  }
  for (const std::string& channel : page.channels)
    if (!image.channels.count(channel))
      throw FormatError(path.string() + ": channel " + channel + " listed in manifest.json " + field + " is missing");
  return image;
}

formats::ProbeGrid load_probes(const fs::path& directory, const ProbeGridInfo& info) {
  const fs::path path = existing_bundle_file(directory, info.file, "probes.file");
  formats::ProbeGrid grid = formats::read_probes_file(path.string());
  const std::string mismatch = path.string() + ": does not match manifest.json probes: ";
  if (grid.counts != info.counts)
    throw FormatError(mismatch + "counts " + std::to_string(grid.counts[0]) + " x " + std::to_string(grid.counts[1]) +
                      " x " + std::to_string(grid.counts[2]) + " vs " + std::to_string(info.counts[0]) + " x " +
                      std::to_string(info.counts[1]) + " x " + std::to_string(info.counts[2]));
  if (grid.sh_order != info.sh_order) throw FormatError(mismatch + "sh_order");
  for (int a = 0; a < 3; ++a) {
    if (!nearly_equal(info.origin[a], grid.origin[a], 0)) throw FormatError(mismatch + "origin");
    if (!nearly_equal(info.spacing[a], grid.spacing[a], 0)) throw FormatError(mismatch + "spacing");
  }
  return grid;
}

formats::SparseVoxelOctree load_svo(const fs::path& directory, const SvoInfo& info) {
  const fs::path path = existing_bundle_file(directory, info.file, "svo.file");
  formats::SparseVoxelOctree svo = formats::read_svo_file(path.string());
  const std::string mismatch = path.string() + ": does not match manifest.json svo: ";
  if (svo.depth != info.depth)
    throw FormatError(mismatch + "depth " + std::to_string(svo.depth) + " vs " + std::to_string(info.depth));
  for (int a = 0; a < 3; ++a) {
    const float magnitude = std::max(svo.size, std::fabs(svo.origin[a]));
    if (!nearly_equal(info.bounds_min[a], svo.origin[a], magnitude) ||
        !nearly_equal(info.bounds_max[a], svo.origin[a] + svo.size, magnitude))
      throw FormatError(mismatch + "bounds are not the octree's cube (origin + size on axis " + std::to_string(a) + ")");
  }
  return svo;
}

}  // namespace

Bundle Bundle::open(const std::string& directory) {
  const fs::path dir(directory);
  std::error_code error;
  if (!fs::is_directory(dir, error)) throw FileAccessError(directory + ": not a bundle folder (no such directory)");
  Bundle bundle;
  bundle.directory_ = directory;
  const fs::path manifest_path = dir / "manifest.json";
  bundle.manifest_ = parse_manifest(read_text_file(manifest_path), manifest_path.string());
  for (size_t p = 0; p < bundle.manifest_.pages.size(); ++p)
    bundle.page_images_.push_back(load_page(dir, bundle.manifest_.pages[p], p));
  if (bundle.manifest_.probes) bundle.probes_ = load_probes(dir, *bundle.manifest_.probes);
  if (bundle.manifest_.svo) bundle.svo_ = load_svo(dir, *bundle.manifest_.svo);
  return bundle;
}

const formats::LightmapImage& Bundle::page_image(size_t page) const {
  if (page >= page_images_.size())
    throw std::out_of_range("page " + std::to_string(page) + " of " + std::to_string(page_images_.size()));
  return page_images_[page];
}

namespace {

// Page UV of an instance's lightmap UV; NaN (from Inf * 0) becomes 0. u, v may overflow to Inf for
// a huge uv; the lookups clamp to the edge either way.
std::array<float, 2> page_uv(const std::vector<InstanceInfo>& instances, size_t instance, std::array<float, 2> uv) {
  if (instance >= instances.size())
    throw std::out_of_range("instance " + std::to_string(instance) + " of " + std::to_string(instances.size()));
  if (!(std::isfinite(uv[0]) && std::isfinite(uv[1]))) throw std::invalid_argument("lightmap uv is not finite");
  const InstanceInfo& info = instances[instance];
  const float u = uv[0] * info.scale_offset[0] + info.scale_offset[2];
  const float v = uv[1] * info.scale_offset[1] + info.scale_offset[3];
  return {std::isnan(u) ? 0.0f : u, std::isnan(v) ? 0.0f : v};
}

}  // namespace

Rgb Bundle::lightmap(size_t instance, std::array<float, 2> uv) const {
  const std::array<float, 2> p = page_uv(manifest_.instances, instance, uv);
  return bilinear_page_rgb(page_images_[manifest_.instances[instance].page], p[0], p[1]);
}

float Bundle::lightmap_channel(size_t instance, const std::string& channel, std::array<float, 2> uv) const {
  const std::array<float, 2> p = page_uv(manifest_.instances, instance, uv);
  const formats::LightmapImage& page = page_images_[manifest_.instances[instance].page];
  if (!page.channels.count(channel))
    throw std::out_of_range(manifest_.pages[manifest_.instances[instance].page].file + ": no channel " + channel);
  return bilinear_page_channel(page, channel, p[0], p[1]);
}

bool Bundle::has_lightmap_channel(const std::string& channel) const {
  for (const formats::LightmapImage& page : page_images_)
    if (!page.channels.count(channel)) return false;
  return !page_images_.empty();
}

ProbeShResult Bundle::probe_sh(Point3 point) const {
  if (!probes_) throw std::logic_error("the bundle has no probes");
  require_finite(point, "probe lookup point");
  return interpolate_probe_sh(*probes_, point);
}

ProbeIrradianceResult Bundle::probe_irradiance_over_pi(Point3 point, Point3 normal) const {
  if (!probes_) throw std::logic_error("the bundle has no probes");
  require_finite(point, "probe lookup point");
  require_direction(normal, "probe lookup normal");
  return loader::probe_irradiance_over_pi(*probes_, point, normal);
}

SvoExitanceResult Bundle::svo_exitance(Point3 point, uint32_t level, Point3 normal) const {
  if (!svo_) throw std::logic_error("the bundle has no SVO");
  require_finite(point, "SVO lookup point");
  require_direction(normal, "SVO lookup normal");
  return lookup_svo_exitance(*svo_, point, level, normal);
}

}  // namespace exitance::loader
