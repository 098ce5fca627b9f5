#include <stdio.h>

#include "exitance/loader/exitance_loader.h"

int open_with_c_api(const char* directory) {
  ExitanceBundle* bundle = NULL;
  float rgb[3];
  if (exitance_bundle_open(directory, &bundle) != EXITANCE_ERROR_NONE) {
    fprintf(stderr, "consumer (C): %s\n", exitance_last_error_message());
    return 1;
  }
  if (exitance_bundle_lightmap(bundle, 0, 0.5f, 0.5f, rgb) != EXITANCE_ERROR_NONE) {
    fprintf(stderr, "consumer (C): %s\n", exitance_last_error_message());
    exitance_bundle_release(bundle);
    return 1;
  }
  printf("C: %u pages, E/pi (%g, %g, %g)\n", exitance_bundle_page_count(bundle), rgb[0], rgb[1], rgb[2]);
  exitance_bundle_release(bundle);
  return 0;
}
