// probes.bin: the light-probe grid on disk (layout in formats/probes_format.md). Writers validate
// the grid first, so a file they write is always one the readers accept; readers validate every
// field before returning, so a returned ProbeGrid is safe to index with ProbeGrid::index.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "exitance/formats/format_error.h"
#include "exitance/formats/probe_grid.h"

namespace exitance::formats {

inline constexpr char kProbesMagic[8] = {'E', 'X', 'P', 'R', 'O', 'B', 'E', 'S'};
constexpr uint32_t kProbesFormatVersion = 1;
constexpr uint32_t kProbesHeaderSize = 80;
constexpr uint32_t kProbeRecordSize = 124;
// Refused above this many probes (about 8 GB of records): a corrupt count must not turn into a
// huge allocation, and no sane grid comes close.
constexpr uint64_t kMaxProbeCount = uint64_t(1) << 26;

// Throws FormatError naming the first probe or field that is wrong (name_for_errors prefixes it).
void validate_probe_grid(const ProbeGrid& grid, const std::string& name_for_errors);

// The exact bytes of probes.bin for a grid; throws FormatError if the grid is invalid.
std::vector<uint8_t> encode_probes(const ProbeGrid& grid);
void write_probes_file(const std::string& path, const ProbeGrid& grid);

// Throws FormatError (FileAccessError when the file cannot be read at all).
ProbeGrid read_probes(const uint8_t* data, size_t size, const std::string& name_for_errors);
ProbeGrid read_probes_file(const std::string& path);

}  // namespace exitance::formats
