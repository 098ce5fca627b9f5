/* A C99 walk through the loader's C API (c_api_walkthrough.c, compiled as C). It records what the
 * API returned; c_api_test.cpp compares that with the closed forms of the test bundle. */
#ifndef EXITANCE_TESTS_C_API_WALKTHROUGH_H
#define EXITANCE_TESTS_C_API_WALKTHROUGH_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct CApiWalkthrough {
  int open_error;
  uint32_t page_count, instance_count;
  uint32_t page0_width, page0_height, page0_channel_count;
  char page0_first_channel[16];
  char instance0_name[32];
  float instance0_scale_offset[4];
  int lightmap_error;
  float lightmap_rgb[3];
  int has_probes, probe_error, probe_usable;
  float probe_sh[27];
  float probe_irradiance[3];
  float probe_origin[3];
  int has_svo, svo_error, svo_found;
  uint32_t svo_level;
  float svo_rgb[3];
  uint32_t svo_depth;
  /* error paths */
  int bad_instance_error, null_argument_error, missing_directory_error, missing_directory_handle_is_null;
  int missing_directory_message_names_it, no_probes_error, last_error_after_success;
} CApiWalkthrough;

/* Returns 0 when the bundle opened; fills *out either way. */
int c_api_walkthrough(const char* bundle_directory, float u, float v, const float point[3], const float normal[3],
                      uint32_t svo_level, CApiWalkthrough* out);

#ifdef __cplusplus
}
#endif

#endif
