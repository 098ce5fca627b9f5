// manifest.json parser: any input is either refused with a FormatError or yields a manifest whose
// instances all name an existing page.
#include "exitance/formats/format_error.h"
#include "exitance/loader/manifest.h"

using namespace exitance;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const loader::Manifest m =
        loader::parse_manifest(std::string_view(reinterpret_cast<const char*>(data), size), "manifest.json");
    for (const loader::InstanceInfo& instance : m.instances)
      if (instance.page >= m.pages.size()) __builtin_trap();
  } catch (const formats::FormatError&) {
  }
  return 0;
}
