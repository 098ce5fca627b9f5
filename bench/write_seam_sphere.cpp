// Writes the seam benchmark's scene (bench/results/seams.md): the sphere over a floor that
// seam_stitching_bake_tests bakes (tests/support/sphere_over_floor_gltf.h), for `bake` to run on.
//   bench_write_seam_sphere OUT.gltf [SEGMENTS RINGS [sun]]
#include <cstdlib>
#include <iostream>
#include <string>

#include "support/sphere_over_floor_gltf.h"

int main(int argc, char** argv) {
  const bool sun = argc == 5 && std::string(argv[4]) == "sun";
  if ((argc != 2 && argc != 4 && argc != 5) || (argc == 5 && !sun)) {
    std::cerr << "usage: bench_write_seam_sphere OUT.gltf [SEGMENTS RINGS [sun]]\n";
    return 2;
  }
  const int segments = argc >= 4 ? std::atoi(argv[2]) : 48, rings = argc >= 4 ? std::atoi(argv[3]) : 24;
  if (segments < 3 || rings < 2 || segments > 4096 || rings > 4096) {
    std::cerr << "bench_write_seam_sphere: SEGMENTS 3..4096 and RINGS 2..4096\n";
    return 2;
  }
  exitance::test::write_sphere_over_floor_gltf(argv[1], segments, rings, sun);
  return 0;
}
