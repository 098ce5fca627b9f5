// probes.bin reader: any input is either refused with a FormatError or yields a grid that
// interpolates anywhere without faults and round-trips through the writer unchanged.
#include <cstring>

#include "exitance/formats/probes_file.h"
#include "probe_lookup.h"

using namespace exitance;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  formats::ProbeGrid grid;
  try {
    grid = formats::read_probes(data, size, "probes.bin");
  } catch (const formats::FormatError&) {
    return 0;  // refused cleanly; any other exception escapes and counts as a crash
  }
  const std::vector<uint8_t> bytes = formats::encode_probes(grid);
  const formats::ProbeGrid again = formats::read_probes(bytes.data(), bytes.size(), "re-encoded");
  if (again.probes.size() != grid.probes.size() ||
      std::memcmp(again.probes.data(), grid.probes.data(), grid.probes.size() * sizeof(formats::ProbeRecord)) != 0)
    __builtin_trap();

  // Points at, between and far outside the grid points.
  for (float f : {-1e30f, -1.0f, 0.0f, 0.37f, 0.5f, 1.0f, 2.5f, 1e30f}) {
    loader::Point3 p{};
    for (int a = 0; a < 3; ++a) p[a] = grid.origin[a] + f * grid.spacing[a] * float(grid.counts[a]);
    loader::interpolate_probe_sh(grid, p);
    loader::probe_irradiance_over_pi(grid, p, {0.0f, 1.0f, 0.0f});
  }
  return 0;
}
