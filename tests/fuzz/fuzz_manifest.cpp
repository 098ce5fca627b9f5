// manifest.json reader and writer: any input is either refused with a FormatError or yields a
// manifest whose instances all name an existing page, and which the writer writes and the reader
// reads back to the same text (one schema for both).
#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/format_error.h"

using namespace exitance;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const formats::BundleManifest m =
        formats::parse_bundle_manifest(std::string_view(reinterpret_cast<const char*>(data), size), "manifest.json");
    for (const formats::InstanceInfo& instance : m.instances)
      if (instance.page >= m.pages.size()) __builtin_trap();
    const std::string written = formats::write_bundle_manifest(m);
    if (formats::write_bundle_manifest(formats::parse_bundle_manifest(written, "written")) != written) __builtin_trap();
  } catch (const formats::FormatError&) {
  }
  return 0;
}
