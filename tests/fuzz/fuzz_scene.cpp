// scene.bin reader: any input is either refused with a FormatError or yields a scene that
//  - re-encodes, in its format version (1 or 2), to exactly the input bytes (the checksums aside:
//    fuzzing builds do not check them),
//  - has a BVH that a traversal with a stack of bvh.stack_entries walks without overflowing it,
//    visiting every node once and reading only existing leaf slots and triangles,
//  - restores into runtime types and decodes its texel G-buffer without faults (AddressSanitizer
//    checks every access), and, when the runtime can write it back, restores again to the same
//    G-buffer bit for bit.
#include <cstring>

#include "exitance/formats/scene_file.h"
#include "exitance/runtime/scene_file_conversion.h"

using namespace exitance;

namespace {

void walk_bvh(const formats::SceneFile& s) {
  const formats::SceneBvh& bvh = s.bvh;
  std::vector<uint32_t> stack{0};
  size_t deepest = stack.size(), visited = 0, slots = 0;
  while (!stack.empty()) {
    const uint32_t node = stack.back();
    stack.pop_back();
    if (node >= bvh.nodes.size() || ++visited > bvh.nodes.size()) __builtin_trap();
    for (uint32_t word : bvh.nodes[node].child) {
      if (word == formats::kSceneBvhEmptyChild) continue;
      if (word & formats::kSceneBvhLeafBit) {
        const uint32_t first = (word & ~formats::kSceneBvhLeafBit) >> 2, count = (word & 3u) + 1;
        for (uint32_t k = first; k < first + count; ++k) {
          const uint32_t triangle = bvh.leaf_triangles.at(k);
          if (triangle >= s.triangles.count()) __builtin_trap();
          ++slots;
        }
      } else {
        stack.push_back(word);
      }
    }
    deepest = std::max(deepest, stack.size());
  }
  if (deepest > bvh.stack_entries || visited != bvh.nodes.size() || slots != bvh.leaf_triangles.size())
    __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  formats::SceneFile scene;
  try {
    scene = formats::read_scene(data, size, "scene.bin");
  } catch (const formats::FormatError&) {
    return 0;  // refused cleanly; any other exception escapes and counts as a crash
  }
  // Re-encoded in the input's own format version (1 or 2; read_scene accepted it, so it is one of them).
  uint32_t version = 0;
  std::memcpy(&version, data + 8, 4);
  const std::vector<uint8_t> bytes = formats::encode_scene(scene, version);
  constexpr size_t kCrcs = formats::kSceneHeaderSize - 8;  // payload and header CRC
  if (bytes.size() != size || std::memcmp(bytes.data(), data, kCrcs) != 0 ||
      std::memcmp(bytes.data() + formats::kSceneHeaderSize, data + formats::kSceneHeaderSize,
                  size - formats::kSceneHeaderSize) != 0)
    __builtin_trap();
  walk_bvh(scene);

  // Restoring allocates the pages' coverage (4 bytes per atlas texel); skip atlases above 64 MB.
  uint64_t atlas_texels = 0;
  for (const formats::TexelPageRecord& page : scene.texels.pages) atlas_texels += uint64_t(page.width) * page.height;
  if (atlas_texels > (uint64_t(1) << 24)) return 0;
  const PersistedScene restored = restore_scene(scene);
  if (restored.gbuffer.texels.size() != scene.texels.texels.size() ||
      restored.scene.triangle_count() != scene.triangles.count() ||
      restored.scene.textures.size() != scene.textures.size() ||
      restored.scene.vertex_color.size() != scene.vertex_color.size() ||
      restored.scene.sky.has_environment() != (scene.sky_environment.width != 0))
    __builtin_trap();
  // Writing it back refuses texels whose normal or albedo the rasterizer's barycentrics for the
  // texel do not give (the codec derives them from the atlas) with a FormatError; what it writes
  // restores to the same G-buffer, bit for bit.
  std::vector<uint8_t> rewritten;
  try {
    rewritten =
        formats::encode_scene(make_scene_file(restored.scene, restored.gbuffer, restored.atlas,
                                              restored.has_probe_grid() ? &restored.probes : nullptr, restored.bvh));
  } catch (const formats::FormatError&) {
    return 0;
  }
  const PersistedScene again = restore_scene(formats::read_scene(rewritten.data(), rewritten.size(), "rewritten"));
  const TexelGBuffer &a = restored.gbuffer, &b = again.gbuffer;
  if (a.texels.size() != b.texels.size() || a.pages.size() != b.pages.size() || a.skipped_texels != b.skipped_texels ||
      (!a.texels.empty() && std::memcmp(a.texels.data(), b.texels.data(), a.texels.size() * sizeof(LiveTexel)) != 0))
    __builtin_trap();
  for (size_t p = 0; p < a.pages.size(); ++p)
    if (a.pages[p].coverage != b.pages[p].coverage) __builtin_trap();
  return 0;
}
