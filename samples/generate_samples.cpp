// generate_samples OUTDIR [--only NAME]: writes the sample scenes as glTF files.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "sample_scenes.h"

namespace {

using exitance::samples::SceneBuilder;

struct SampleScene {
  const char* name;
  void (*build)(SceneBuilder&);
};

constexpr SampleScene kScenes[] = {
    {"cornell_room", exitance::samples::buildCornellRoom},
    {"courtyard", exitance::samples::buildCourtyard},
    {"building", exitance::samples::buildBuilding},
    {"ajar_room", exitance::samples::buildAjarRoom},
    {"thin_walls", exitance::samples::buildThinWalls},
    {"open_city", exitance::samples::buildOpenCity},
};

int usage() {
  std::fprintf(stderr, "usage: generate_samples OUTDIR [--only NAME]\n  scenes:");
  for (const SampleScene& scene : kScenes) std::fprintf(stderr, " %s", scene.name);
  std::fprintf(stderr, "\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && !(argc == 4 && std::string(argv[2]) == "--only")) return usage();
  const std::filesystem::path outDir = argv[1];
  const std::string only = argc == 4 ? argv[3] : "";

  bool matched = false;
  try {
    std::filesystem::create_directories(outDir);
    for (const SampleScene& sample : kScenes) {
      if (!only.empty() && only != sample.name) continue;
      matched = true;
      SceneBuilder scene;
      sample.build(scene);
      const std::filesystem::path file = outDir / (std::string(sample.name) + ".gltf");
      scene.write(file.string());
      std::printf("%s: %zu triangles, %zu instances of %zu meshes\n", file.string().c_str(), scene.triangleCount(),
                  scene.instanceCount(), scene.meshCount());
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "generate_samples: %s\n", error.what());
    return 1;
  }
  if (!matched) {
    std::fprintf(stderr, "generate_samples: no scene named '%s'\n", only.c_str());
    return usage();
  }
  return 0;
}
