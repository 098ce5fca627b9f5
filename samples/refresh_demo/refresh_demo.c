/* exitance_refresh_demo: the runtime from an engine's side. Links only libexitance_runtime and the
 * loader (DESIGN §2). Moves a node of a baked bundle along a straight line over N frames; each frame
 * applies the edit, refreshes within a budget, and appends lightmap page 0 (tone-mapped) to a strip
 * image a person can look at (binary PPM, the frames side by side). The last frame's bundle is
 * written and opened with the loader.
 *
 *   exitance_refresh_demo BUNDLE NODE FROM_X,Y,Z TO_X,Y,Z STRIP.ppm [FRAMES] [SAMPLES_PER_FRAME] [BUDGET_MS]
 *
 * e.g. exitance_refresh_demo build/samples/cornell_room.bake TallBox -0.7,0,-0.6 -0.1,0,0.3 strip.ppm 6 16
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exitance/loader/exitance_loader.h"
#include "exitance/runtime/exitance_runtime.h"

static int parse_point(const char* text, double p[3]) { return sscanf(text, "%lf,%lf,%lf", &p[0], &p[1], &p[2]) == 3; }

/* E/pi to a displayable byte: exposure, x / (1 + x), sRGB transfer. */
static unsigned char display(float value) {
  double x = value > 0 ? value * 2.0 : 0.0;
  x = x / (1.0 + x);
  x = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
  return (unsigned char)(x * 255.0 + 0.5);
}

static int runtime_error(const char* call) {
  fprintf(stderr, "exitance_refresh_demo: %s: %s\n", call, exitance_runtime_last_error_message());
  return 2;
}

int main(int argc, char** argv) {
  double from[3], to[3];
  if (argc < 6 || !parse_point(argv[3], from) || !parse_point(argv[4], to)) {
    fprintf(stderr, "usage: %s BUNDLE NODE FROM_X,Y,Z TO_X,Y,Z STRIP.ppm [FRAMES] [SAMPLES_PER_FRAME] [BUDGET_MS]\n", argv[0]);
    return 2;
  }
  const char* bundle = argv[1];
  const char* node = argv[2];
  const char* strip_path = argv[5];
  const int frames = argc > 6 ? atoi(argv[6]) : 6;
  const unsigned samples = argc > 7 ? (unsigned)atoi(argv[7]) : 16u;
  const double budget_ms = argc > 8 ? atof(argv[8]) : 0.0;
  if (frames < 1 || frames > 1000 || samples < 1 || !(budget_ms >= 0)) {
    fprintf(stderr, "exitance_refresh_demo: FRAMES must be 1..1000, SAMPLES_PER_FRAME >= 1, BUDGET_MS >= 0\n");
    return 2;
  }

  ExitanceRuntime* rt = NULL;
  if (exitance_runtime_open(bundle, NULL, &rt) != EXITANCE_RUNTIME_OK) return runtime_error("open");
  ExitanceRuntimePageInfo page;
  if (exitance_runtime_page_info(rt, 0, &page) != EXITANCE_RUNTIME_OK) return runtime_error("page_info");
  const size_t texels = (size_t)page.width * page.height;
  float* rgb = malloc(texels * 3 * sizeof(float));
  unsigned char* strip = malloc(texels * 3 * (size_t)frames);
  if (!rgb || !strip) return 1;

  for (int f = 0; f < frames; ++f) {
    const double t = frames > 1 ? (double)f / (frames - 1) : 0.0;
    char edits[512];
    snprintf(edits, sizeof edits, "{\"edits\": [{\"node\": \"%s\", \"translation\": [%.9g, %.9g, %.9g]}]}", node,
             from[0] + (to[0] - from[0]) * t, from[1] + (to[1] - from[1]) * t, from[2] + (to[2] - from[2]) * t);
    if (exitance_runtime_apply_edits(rt, edits) != EXITANCE_RUNTIME_OK) return runtime_error("apply_edits");
    ExitanceRefreshReport report;
    if (exitance_runtime_refresh(rt, budget_ms, samples, &report) != EXITANCE_RUNTIME_OK) return runtime_error("refresh");
    double relative_mse = 0;
    if (exitance_runtime_estimated_relative_mse(rt, &relative_mse) != EXITANCE_RUNTIME_OK) return runtime_error("error");
    if (exitance_runtime_read_page(rt, 0, rgb, page.width, page.height) != EXITANCE_RUNTIME_OK) return runtime_error("read_page");
    for (uint32_t y = 0; y < page.height; ++y)
      for (uint32_t x = 0; x < page.width; ++x)
        for (int c = 0; c < 3; ++c)
          strip[((size_t)y * page.width * frames + (size_t)f * page.width + x) * 3 + c] =
              display(rgb[((size_t)y * page.width + x) * 3 + c]);
    printf("frame %d: %s at %.3f of the way, %u samples per texel in %.1f ms, estimated relMSE %.4g\n", f, node, t,
           report.samples_per_texel, report.milliseconds, relative_mse);
  }

  FILE* out = fopen(strip_path, "wb");
  if (!out) {
    fprintf(stderr, "exitance_refresh_demo: %s: cannot write\n", strip_path);
    return 1;
  }
  fprintf(out, "P6\n%u %u\n255\n", page.width * (unsigned)frames, page.height);
  fwrite(strip, 1, texels * 3 * (size_t)frames, out);
  fclose(out);

  /* The last frame as a bundle, opened by the loader as an engine would at load time. */
  char written[4096];
  snprintf(written, sizeof written, "%s.bake", strip_path);
  if (exitance_runtime_write_bundle(rt, written) != EXITANCE_RUNTIME_OK) return runtime_error("write_bundle");
  exitance_runtime_release(rt);
  ExitanceBundle* loaded = NULL;
  if (exitance_bundle_open(written, &loaded) != EXITANCE_ERROR_NONE) {
    fprintf(stderr, "exitance_refresh_demo: %s\n", exitance_last_error_message());
    return 1;
  }
  printf("wrote %s (%u x %u, %d frames) and %s (%u pages)\n", strip_path, page.width * (unsigned)frames, page.height,
         frames, written, exitance_bundle_page_count(loaded));
  exitance_bundle_release(loaded);
  free(rgb);
  free(strip);
  return 0;
}
