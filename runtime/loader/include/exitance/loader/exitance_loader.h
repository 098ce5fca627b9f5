/* Exitance loader, C API (C99). Opaque handles with explicit ownership and returned, queryable
 * errors, in the style of Embree's API. The C++ API (exitance/loader/bundle.h) is the same library.
 *
 *   ExitanceBundle* bundle = NULL;
 *   if (exitance_bundle_open("scene.bake", &bundle) != EXITANCE_ERROR_NONE) {
 *     fprintf(stderr, "%s\n", exitance_last_error_message());
 *     return 1;
 *   }
 *   float rgb[3];
 *   exitance_bundle_lightmap(bundle, 0, 0.5f, 0.5f, rgb);   // E/pi
 *   exitance_bundle_release(bundle);
 *
 * Every function sets this thread's last error (EXITANCE_ERROR_NONE on success); the message
 * stays valid until the next call of this API on the same thread. A handle is immutable once
 * opened: lookups may run from several threads at once. Returned strings belong to the handle.
 */
#ifndef EXITANCE_LOADER_H
#define EXITANCE_LOADER_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ExitanceBundle ExitanceBundle;

typedef enum ExitanceError {
  EXITANCE_ERROR_NONE = 0,
  EXITANCE_ERROR_INVALID_ARGUMENT = 1, /* NULL pointer, index out of range, non-finite point, zero normal */
  EXITANCE_ERROR_IO = 2,               /* a bundle file is missing or cannot be read */
  EXITANCE_ERROR_INVALID_FILE = 3,     /* a bundle file is malformed, of another version, or contradicts the manifest */
  EXITANCE_ERROR_NOT_PRESENT = 4,      /* the bundle has no probes / no SVO */
  EXITANCE_ERROR_OUT_OF_MEMORY = 5,
  EXITANCE_ERROR_UNKNOWN = 6
} ExitanceError;

typedef struct ExitancePageInfo {
  uint32_t width;
  uint32_t height;
  uint32_t channel_count; /* names: exitance_bundle_page_channel */
  const char* file;       /* relative to the bundle folder */
} ExitancePageInfo;

typedef struct ExitanceInstanceInfo {
  uint32_t node; /* glTF node index */
  uint32_t mesh; /* glTF mesh index */
  uint32_t page;
  float scale_offset[4]; /* page UV = TEXCOORD_1 * (s[0], s[1]) + (s[2], s[3]) */
  const char* name;
} ExitanceInstanceInfo;

typedef struct ExitanceProbeGridInfo {
  float origin[3];  /* position of probe (0,0,0) */
  float spacing[3];
  uint32_t counts[3];
} ExitanceProbeGridInfo;

typedef struct ExitanceSvoInfo {
  float bounds_min[3]; /* the octree's cube */
  float bounds_max[3];
  uint32_t depth;      /* leaf level */
} ExitanceSvoInfo;

/* Reads and validates the whole bundle. On success *out_bundle holds one reference; on failure
 * it is set to NULL and the error message names the file, the element and the problem. */
ExitanceError exitance_bundle_open(const char* directory, ExitanceBundle** out_bundle);
void exitance_bundle_retain(ExitanceBundle* bundle);
/* Drops one reference; the last one frees the bundle. NULL is ignored. */
void exitance_bundle_release(ExitanceBundle* bundle);

/* The error of this thread's most recent call, and its one-line message ("" when none). */
ExitanceError exitance_last_error(void);
const char* exitance_last_error_message(void);

uint32_t exitance_bundle_page_count(const ExitanceBundle* bundle);
ExitanceError exitance_bundle_page(const ExitanceBundle* bundle, uint32_t page, ExitancePageInfo* out_info);
/* NULL when page or channel is out of range. */
const char* exitance_bundle_page_channel(const ExitanceBundle* bundle, uint32_t page, uint32_t channel);

uint32_t exitance_bundle_instance_count(const ExitanceBundle* bundle);
ExitanceError exitance_bundle_instance(const ExitanceBundle* bundle, uint32_t instance, ExitanceInstanceInfo* out_info);

/* E/pi (RGB) at an instance's TEXCOORD_1 (u, v): bilinear, clamp to edge. */
ExitanceError exitance_bundle_lightmap(const ExitanceBundle* bundle, uint32_t instance, float u, float v, float out_rgb[3]);

/* 1 when the bundle has a probe grid, else 0. */
int exitance_bundle_has_probes(const ExitanceBundle* bundle);
ExitanceError exitance_bundle_probe_grid(const ExitanceBundle* bundle, ExitanceProbeGridInfo* out_info);
/* Trilinear SH of incident radiance at a point, 9 RGB coefficients (coefficient i, channel c at
 * out_sh[i * 3 + c]), unusable probes weighted out. *out_usable = 0 (and zeros) when no probe of
 * the cell is usable. out_usable may be NULL. */
ExitanceError exitance_bundle_probe_sh(const ExitanceBundle* bundle, const float point[3], float out_sh[27],
                                       int* out_usable);
/* E(n)/pi (RGB) from the interpolated SH for a surface of normal n (need not be unit length). */
ExitanceError exitance_bundle_probe_irradiance_over_pi(const ExitanceBundle* bundle, const float point[3],
                                                       const float normal[3], float out_rgb[3], int* out_usable);

/* 1 when the bundle has a sparse voxel octree, else 0. */
int exitance_bundle_has_svo(const ExitanceBundle* bundle);
ExitanceError exitance_bundle_svo_info(const ExitanceBundle* bundle, ExitanceSvoInfo* out_info);
/* Radiant exitance (RGB) of the octree node containing the point at max_level (or the deepest
 * existing node above it), on the side facing the normal. *out_found = 0 (and zeros) outside the
 * octree's cube. out_level_reached and out_found may be NULL. */
ExitanceError exitance_bundle_svo_exitance(const ExitanceBundle* bundle, const float point[3], uint32_t max_level,
                                           const float normal[3], float out_rgb[3], uint32_t* out_level_reached,
                                           int* out_found);

#ifdef __cplusplus
}
#endif

#endif /* EXITANCE_LOADER_H */
