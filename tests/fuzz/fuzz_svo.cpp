// svo.bin reader: any input is either refused with a FormatError or yields an octree in which
// svo_find_node and the exitance lookup stay inside the node array for any point and level
// (AddressSanitizer checks every access), and which round-trips through the writer unchanged.
#include <cstring>

#include "exitance/formats/svo_file.h"
#include "svo_lookup.h"

using namespace exitance;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  formats::SparseVoxelOctree svo;
  try {
    svo = formats::read_svo(data, size, "svo.bin");
  } catch (const formats::FormatError&) {
    return 0;  // refused cleanly; any other exception escapes and counts as a crash
  }
  const std::vector<uint8_t> bytes = formats::encode_svo(svo);
  const formats::SparseVoxelOctree again = formats::read_svo(bytes.data(), bytes.size(), "re-encoded");
  if (again.nodes.size() != svo.nodes.size() || again.level_begin != svo.level_begin ||
      (!svo.nodes.empty() &&  // memcmp on the null data() of an empty vector is undefined
       std::memcmp(again.nodes.data(), svo.nodes.data(), svo.nodes.size() * sizeof(formats::SvoNode)) != 0))
    __builtin_trap();

  // A lattice of points over (and just beyond) the cube, at every level up to past the depth; the
  // lattice is offset by a fraction taken from the input so different inputs probe different cells.
  const float jitter = size ? float(data[size / 2]) / 256.0f : 0.5f;
  constexpr int kSteps = 9;
  for (int i = 0; i < kSteps * kSteps * kSteps; ++i) {
    loader::Point3 p{};
    const int step[3] = {i % kSteps, (i / kSteps) % kSteps, i / (kSteps * kSteps)};
    for (int a = 0; a < 3; ++a) p[a] = svo.origin[a] + svo.size * ((float(step[a]) + jitter) / float(kSteps - 2) - 0.1f);
    for (uint32_t level = 0; level <= svo.depth + 1; ++level) {
      const loader::SvoExitanceResult r = loader::lookup_svo_exitance(svo, p, level, {0.0f, 1.0f, 0.0f});
      if (r.found && (r.node >= svo.nodes.size() || r.level > level || r.level > svo.depth)) __builtin_trap();
    }
  }
  return 0;
}
