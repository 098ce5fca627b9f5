#include "exitance/formats/probes_file.h"

#include <cmath>

#include "binary_io.h"
#include "framed_file.h"

namespace exitance::formats {
namespace {

constexpr framing::FileKind kProbesKind{kProbesMagic, kProbesFormatVersion, kProbesHeaderSize, kProbesFormatVersion};
constexpr uint32_t kSupportedShOrder = 2;  // L2: 9 coefficients, the only order ProbeRecord holds
constexpr uint32_t kHighestProbeState = uint32_t(ProbeState::Skipped);

std::string xyz(const std::array<uint32_t, 3>& v) {
  return std::to_string(v[0]) + " x " + std::to_string(v[1]) + " x " + std::to_string(v[2]);
}

// Checks the grid description (everything but the records); shared by the reader, which must
// check it before sizing anything from it, and the writer.
uint64_t checked_probe_count(const ProbeGrid& grid, const std::string& name) {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(grid.origin[a])) throw FormatError(name + ": header: origin is not finite");
    if (!(std::isfinite(grid.spacing[a]) && grid.spacing[a] > 0))
      throw FormatError(name + ": header: spacing " + std::to_string(grid.spacing[a]) + " on axis " +
                        std::to_string(a) + " is not a positive finite number");
    if (grid.counts[a] == 0) throw FormatError(name + ": header: counts " + xyz(grid.counts) + " include a zero");
  }
  if (grid.sh_order != kSupportedShOrder)
    throw FormatError(name + ": header: sh_order " + std::to_string(grid.sh_order) + " is not supported (only 2)");
  // Each count is below 2^32: multiply pairwise and cap after each step to stay inside 64 bits.
  const uint64_t xy = uint64_t(grid.counts[0]) * grid.counts[1];
  if (xy > kMaxProbeCount || xy * grid.counts[2] > kMaxProbeCount)
    throw FormatError(name + ": header: counts " + xyz(grid.counts) + " exceed the limit of " +
                      std::to_string(kMaxProbeCount) + " probes");
  return xy * grid.counts[2];
}

void validate_probe_record(const ProbeRecord& p, size_t index, const std::string& name) {
  const std::string where = name + ": probe " + std::to_string(index) + ": ";
  for (float v : p.position)
    if (!std::isfinite(v)) throw FormatError(where + "position is not finite");
  if (uint32_t(p.state) > kHighestProbeState)
    throw FormatError(where + "state " + std::to_string(uint32_t(p.state)) + " is not a known ProbeState (0..3)");
  for (size_t i = 0; i < p.sh.size(); ++i)
    if (!std::isfinite(p.sh[i]))
      throw FormatError(where + "SH coefficient " + std::to_string(i / 3) + " channel " + std::to_string(i % 3) +
                        " is not finite");
}

}  // namespace

void validate_probe_grid(const ProbeGrid& grid, const std::string& name) {
  const uint64_t count = checked_probe_count(grid, name);
  if (grid.probes.size() != count)
    throw FormatError(name + ": " + std::to_string(grid.probes.size()) + " probes for a grid of " + xyz(grid.counts));
  for (size_t i = 0; i < grid.probes.size(); ++i) validate_probe_record(grid.probes[i], i, name);
}

std::vector<uint8_t> encode_probes(const ProbeGrid& grid) {
  validate_probe_grid(grid, "probes.bin (writing)");
  std::vector<uint8_t> header;
  binary_io::LittleEndianWriter h(header);
  for (float v : grid.origin) h.f32(v);
  for (float v : grid.spacing) h.f32(v);
  for (uint32_t v : grid.counts) h.u32(v);
  h.u32(grid.sh_order);
  h.u32(uint32_t(grid.probes.size()));
  h.u32(kProbeRecordSize);

  std::vector<uint8_t> payload;
  payload.reserve(grid.probes.size() * kProbeRecordSize);
  binary_io::LittleEndianWriter p(payload);
  for (const ProbeRecord& probe : grid.probes) {
    for (float v : probe.position) p.f32(v);
    p.u32(uint32_t(probe.state));
    for (float v : probe.sh) p.f32(v);
  }
  return framing::build_frame(kProbesKind, header, payload);
}

void write_probes_file(const std::string& path, const ProbeGrid& grid) {
  binary_io::write_whole_file(path, encode_probes(grid));
}

ProbeGrid read_probes(const uint8_t* data, size_t size, const std::string& name) {
  const framing::FramedView frame = framing::open_frame(data, size, kProbesKind, name);
  binary_io::LittleEndianReader h(frame.header, kProbesHeaderSize, name);
  h.skip(16);
  ProbeGrid grid;
  for (float& v : grid.origin) v = h.f32();
  for (float& v : grid.spacing) v = h.f32();
  for (uint32_t& v : grid.counts) v = h.u32();
  grid.sh_order = h.u32();
  const uint32_t stored_count = h.u32();
  const uint32_t record_size = h.u32();

  const uint64_t count = checked_probe_count(grid, name);
  if (stored_count != count)
    throw FormatError(name + ": header: probe count " + std::to_string(stored_count) + " is not " + xyz(grid.counts));
  if (record_size != kProbeRecordSize)
    throw FormatError(name + ": header: probe record size " + std::to_string(record_size) + " is not " +
                      std::to_string(kProbeRecordSize));
  if (frame.payload_size != count * kProbeRecordSize)
    throw FormatError(name + ": payload: " + std::to_string(frame.payload_size) + " bytes, " + std::to_string(count) +
                      " probes need " + std::to_string(count * kProbeRecordSize));

  // The payload size now bounds the count, so this allocation is backed by real bytes.
  grid.probes.resize(size_t(count));
  binary_io::LittleEndianReader p(frame.payload, size_t(frame.payload_size), name);
  for (size_t i = 0; i < grid.probes.size(); ++i) {
    ProbeRecord& probe = grid.probes[i];
    for (float& v : probe.position) v = p.f32();
    probe.state = ProbeState(p.u32());
    for (float& v : probe.sh) v = p.f32();
    validate_probe_record(probe, i, name);
  }
  return grid;
}

ProbeGrid read_probes_file(const std::string& path) {
  const std::vector<uint8_t> bytes = binary_io::read_whole_file(path);
  return read_probes(bytes.data(), bytes.size(), path);
}

}  // namespace exitance::formats
