/* Compiled as strict C99 (-std=c99 -pedantic-errors): proves exitance_loader.h is a C header. */
#include "c_api_walkthrough.h"

#include <stdio.h>
#include <string.h>

#include "exitance/loader/exitance_loader.h"

static void copy_text(char* out, size_t size, const char* text) {
  if (!text) text = "";
  strncpy(out, text, size - 1);
  out[size - 1] = '\0';
}

int c_api_walkthrough(const char* bundle_directory, float u, float v, const float point[3], const float normal[3],
                      uint32_t svo_level, CApiWalkthrough* out) {
  ExitanceBundle* bundle = NULL;
  ExitanceBundle* missing = (ExitanceBundle*)1; /* must come back NULL */
  ExitancePageInfo page;
  ExitanceInstanceInfo instance;
  ExitanceProbeGridInfo grid;
  ExitanceSvoInfo svo;
  float rgb[3];
  char missing_path[1024];

  memset(out, 0, sizeof(*out));
  snprintf(missing_path, sizeof(missing_path), "%s/does-not-exist", bundle_directory);
  out->missing_directory_error = (int)exitance_bundle_open(missing_path, &missing);
  out->missing_directory_handle_is_null = missing == NULL;
  out->missing_directory_message_names_it = strstr(exitance_last_error_message(), "does-not-exist") != NULL;
  out->null_argument_error = (int)exitance_bundle_open(NULL, &bundle);

  out->open_error = (int)exitance_bundle_open(bundle_directory, &bundle);
  if (out->open_error != EXITANCE_ERROR_NONE) return 1;
  out->last_error_after_success = (int)exitance_last_error();

  out->page_count = exitance_bundle_page_count(bundle);
  out->instance_count = exitance_bundle_instance_count(bundle);
  if (exitance_bundle_page(bundle, 0, &page) == EXITANCE_ERROR_NONE) {
    out->page0_width = page.width;
    out->page0_height = page.height;
    out->page0_channel_count = page.channel_count;
    copy_text(out->page0_first_channel, sizeof(out->page0_first_channel), exitance_bundle_page_channel(bundle, 0, 0));
  }
  if (exitance_bundle_instance(bundle, 0, &instance) == EXITANCE_ERROR_NONE) {
    copy_text(out->instance0_name, sizeof(out->instance0_name), instance.name);
    memcpy(out->instance0_scale_offset, instance.scale_offset, sizeof(instance.scale_offset));
  }
  out->lightmap_error = (int)exitance_bundle_lightmap(bundle, 0, u, v, out->lightmap_rgb);
  out->bad_instance_error = (int)exitance_bundle_lightmap(bundle, out->instance_count, u, v, rgb);

  out->has_probes = exitance_bundle_has_probes(bundle);
  if (out->has_probes) {
    out->probe_error = (int)exitance_bundle_probe_sh(bundle, point, out->probe_sh, &out->probe_usable);
    if (out->probe_error == EXITANCE_ERROR_NONE)
      out->probe_error = (int)exitance_bundle_probe_irradiance_over_pi(bundle, point, normal, out->probe_irradiance, NULL);
    if (exitance_bundle_probe_grid(bundle, &grid) == EXITANCE_ERROR_NONE) memcpy(out->probe_origin, grid.origin, sizeof(grid.origin));
  } else {
    out->no_probes_error = (int)exitance_bundle_probe_sh(bundle, point, out->probe_sh, NULL);
  }

  out->has_svo = exitance_bundle_has_svo(bundle);
  if (out->has_svo) {
    out->svo_error = (int)exitance_bundle_svo_exitance(bundle, point, svo_level, normal, out->svo_rgb, &out->svo_level,
                                                       &out->svo_found);
    if (exitance_bundle_svo_info(bundle, &svo) == EXITANCE_ERROR_NONE) out->svo_depth = svo.depth;
  }

  /* A second reference outlives the first release. */
  exitance_bundle_retain(bundle);
  exitance_bundle_release(bundle);
  out->page_count = exitance_bundle_page_count(bundle) == out->page_count ? out->page_count : 0;
  exitance_bundle_release(bundle);
  exitance_bundle_release(NULL);
  return 0;
}
