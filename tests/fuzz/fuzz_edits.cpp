// EDITS.json reader and the edits themselves (runtime/include/exitance/runtime/refresh/scene_edits.h):
// any input is either refused with a SceneEditError (the scene untouched) or parses into edits
// that, applied to the tests' sample scene, leave every position, normal and light finite.
#include <cmath>
#include <cstring>

#include "exitance/runtime/refresh/scene_edits.h"
#include "sample_scene_file.h"

using namespace exitance;

namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

const PersistedScene& sample() {
  static const PersistedScene scene = restore_scene(exitance::test::make_sample_scene_file());
  return scene;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<SceneEdit> edits;
  try {
    edits = parse_scene_edits(std::string_view(reinterpret_cast<const char*>(data), size), "edits.json");
  } catch (const SceneEditError&) {
    return 0;
  }
  PersistedScene scene = sample();
  try {
    apply_scene_edits(scene, edits);
  } catch (const SceneEditError&) {
    // All or nothing: a refused edit leaves the scene as it was.
    if (scene.scene.positions.size() != sample().scene.positions.size()) __builtin_trap();
    for (size_t i = 0; i < scene.scene.positions.size(); ++i)
      if (std::memcmp(&scene.scene.positions[i], &sample().scene.positions[i], sizeof(Vec3)) != 0) __builtin_trap();
    return 0;
  }
  for (const Vec3& p : scene.scene.positions)
    if (!finite(p)) __builtin_trap();
  for (const Vec3& n : scene.scene.normals)
    if (!finite(n)) __builtin_trap();
  for (const PunctualLight& l : scene.scene.lights)
    if (!finite(l.position) || !finite(l.direction) || !finite(l.intensity)) __builtin_trap();
  for (const LiveTexel& t : scene.gbuffer.texels)
    if (!finite(t.position) || !finite(t.shading_normal)) __builtin_trap();
  return 0;
}
