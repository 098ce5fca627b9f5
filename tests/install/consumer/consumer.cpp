// Opens a bundle with the C++ API and with the C API (consumer_c.c) and reads one value of each kind.
#include <cstdio>
#include <exception>

#include "exitance/loader/bundle.h"

extern "C" int open_with_c_api(const char* directory);

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  try {
    const auto bundle = exitance::loader::Bundle::open(argv[1]);
    const auto e = bundle.lightmap(0, {0.5f, 0.5f});
    std::printf("C++: %zu pages, E/pi (%g, %g, %g)\n", bundle.pages().size(), e[0], e[1], e[2]);
    if (bundle.has_probes()) std::printf("C++: probe E/pi %g\n", bundle.probe_irradiance_over_pi({0, 0, 3}, {0, 1, 0}).irradiance_over_pi[0]);
    if (bundle.has_svo()) std::printf("C++: svo level %u\n", bundle.svo_exitance({1, 1, 1}, 8, {0, 1, 0}).level);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
  return open_with_c_api(argv[1]);
}
