// The light-probe grid of a bake, in memory exactly as probes.bin stores it (probes_format.md):
// a regular grid, x fastest, then y, then z; per probe its (possibly moved) position, its state
// and 9 RGB coefficients of incident radiance L(w) in the real L2 SH basis, Sloan's ordering
// (index l*(l+1)+m), evaluated on world directions.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace exitance::formats {

enum class ProbeState : uint32_t {
  Valid = 0,    // at its grid position, in free space
  Moved = 1,    // its grid position was inside geometry; moved to nearby free space (position says where)
  Invalid = 2,  // inside geometry and no free space nearby: coefficients are zero, lookups weight it out
  Skipped = 3,  // far from all geometry: not traced, coefficients are zero, lookups weight it out
};

struct ProbeRecord {
  std::array<float, 3> position{0, 0, 0};
  ProbeState state = ProbeState::Valid;
  std::array<float, 27> sh{};  // coefficient i, channel c at [i * 3 + c]
};
static_assert(sizeof(ProbeRecord) == 124, "probes.bin probe record is 124 bytes");

struct ProbeGrid {
  std::array<float, 3> origin{0, 0, 0};   // position of probe (0,0,0) before any move
  std::array<float, 3> spacing{1, 1, 1};
  std::array<uint32_t, 3> counts{0, 0, 0};
  uint32_t sh_order = 2;
  std::vector<ProbeRecord> probes;  // counts[0] * counts[1] * counts[2]

  size_t index(uint32_t x, uint32_t y, uint32_t z) const {
    return (size_t(z) * counts[1] + y) * counts[0] + x;
  }
};

inline bool probe_is_usable(const ProbeRecord& p) {
  return p.state == ProbeState::Valid || p.state == ProbeState::Moved;
}

}  // namespace exitance::formats
