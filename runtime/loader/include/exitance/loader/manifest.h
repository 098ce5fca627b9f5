// manifest.json of a bundle as the loader sees it: the schema, reader and writer live in formats/
// (exitance/formats/bundle_manifest.h); these are the loader's names for them.
#pragma once
#include <string>
#include <string_view>

#include "exitance/formats/bundle_manifest.h"

namespace exitance::loader {

using formats::kManifestFormatVersion;
using Manifest = formats::BundleManifest;
using PageInfo = formats::PageInfo;
using InstanceInfo = formats::InstanceInfo;
using ProbeGridInfo = formats::ProbeGridInfo;
using SvoInfo = formats::SvoInfo;

// Checks every field the loader uses for presence, type and range; throws formats::FormatError
// naming the field. name_for_errors prefixes every message (normally the manifest's path).
inline Manifest parse_manifest(std::string_view json_text, const std::string& name_for_errors) {
  return formats::parse_bundle_manifest(json_text, name_for_errors);
}

}  // namespace exitance::loader
