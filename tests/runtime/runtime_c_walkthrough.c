/* The runtime's C API from strict C99: open a bundle, edit, refresh one frame, read a page back,
 * write the refreshed bundle. Returns 0, or the failing call's error code with its message. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exitance/runtime/exitance_runtime.h"

int runtime_c_walkthrough(const char* bundle, const char* output, char* message, size_t message_size);

static int fail(ExitanceRuntime* rt, ExitanceRuntimeError code, char* message, size_t message_size) {
  snprintf(message, message_size, "%s", exitance_runtime_last_error_message());
  exitance_runtime_release(rt);
  return (int)code;
}

int runtime_c_walkthrough(const char* bundle, const char* output, char* message, size_t message_size) {
  ExitanceRuntime* rt = NULL;
  ExitanceRuntimeOptions options;
  ExitanceRefreshReport report;
  ExitanceRuntimePageInfo page;
  ExitanceRuntimeError code;
  float* rgb;
  double relative_mse = 0;
  options.device_index = -1;
  options.has_seed = 1;
  options.seed = 7;
  options.light_layers_off = 0;
  code = exitance_runtime_open(bundle, &options, &rt);
  if (code != EXITANCE_RUNTIME_OK) return fail(NULL, code, message, message_size);
  code = exitance_runtime_apply_edits(rt, "{\"edits\": [{\"material\": \"CeilingLight\", \"emissiveStrength\": 2.0}]}");
  if (code != EXITANCE_RUNTIME_OK) return fail(rt, code, message, message_size);
  code = exitance_runtime_refresh(rt, 0.0, 3, &report);
  if (code != EXITANCE_RUNTIME_OK) return fail(rt, code, message, message_size);
  if (report.samples_per_texel != 3 || !report.capped) {
    snprintf(message, message_size, "refresh: %u samples per texel", (unsigned)report.samples_per_texel);
    exitance_runtime_release(rt);
    return -1;
  }
  code = exitance_runtime_estimated_relative_mse(rt, &relative_mse);
  if (code != EXITANCE_RUNTIME_OK) return fail(rt, code, message, message_size);
  code = exitance_runtime_page_info(rt, 0, &page);
  if (code != EXITANCE_RUNTIME_OK) return fail(rt, code, message, message_size);
  rgb = (float*)malloc(sizeof(float) * 3 * page.width * page.height);
  code = exitance_runtime_read_page(rt, 0, rgb, page.width, page.height);
  free(rgb);
  if (code != EXITANCE_RUNTIME_OK) return fail(rt, code, message, message_size);
  code = exitance_runtime_write_bundle(rt, output);
  if (code != EXITANCE_RUNTIME_OK) return fail(rt, code, message, message_size);
  exitance_runtime_release(rt);
  snprintf(message, message_size, "relMSE %g", relative_mse);
  return 0;
}
