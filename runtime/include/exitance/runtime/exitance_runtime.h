/* Exitance runtime, C API (C99): a baked bundle's lighting kept resident on a Vulkan device and
 * refreshed within a per-call budget after edits (docs/runtime.md). The C++ API is
 * exitance/runtime/refresh/refresh_session.h, in the same library (libexitance_runtime).
 *
 *   ExitanceRuntime* rt = NULL;
 *   if (exitance_runtime_open("scene.bake", NULL, &rt) != EXITANCE_RUNTIME_OK) {
 *     fprintf(stderr, "%s\n", exitance_runtime_last_error_message());
 *     return 1;
 *   }
 *   exitance_runtime_apply_edits(rt, "{\"edits\": [{\"light\": \"Lamp\", \"intensity\": 5}]}");
 *   ExitanceRefreshReport report;
 *   exitance_runtime_refresh(rt, 16.0, 0, &report);     // one frame of at most 16 ms
 *   exitance_runtime_read_page(rt, 0, rgb, width, height); // E/pi of page 0, RGB floats
 *   exitance_runtime_release(rt);
 *
 * Every function sets this thread's last error (EXITANCE_RUNTIME_OK on success); the message
 * stays valid until the next call of this API on the same thread. A handle is used by one thread
 * at a time. A call that fails changes nothing (an edit is all or nothing).
 */
#ifndef EXITANCE_RUNTIME_H
#define EXITANCE_RUNTIME_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ExitanceRuntime ExitanceRuntime;

typedef enum ExitanceRuntimeError {
  EXITANCE_RUNTIME_OK = 0,
  EXITANCE_RUNTIME_INVALID_ARGUMENT = 1, /* NULL pointer, index or size out of range, non-finite or negative budget */
  EXITANCE_RUNTIME_BAD_BUNDLE = 2,       /* a bundle file is missing, malformed or has no scene.bin */
  EXITANCE_RUNTIME_BAD_EDIT = 3,         /* an edit is malformed or names nothing; the state is unchanged */
  EXITANCE_RUNTIME_NO_DEVICE = 4,        /* no usable Vulkan device, or the scene needs what the GPU backend lacks */
  EXITANCE_RUNTIME_DEVICE_FAILED = 5,    /* device lost, out of device memory, a submission timed out */
  EXITANCE_RUNTIME_IO = 6,               /* a bundle could not be written */
  EXITANCE_RUNTIME_UNKNOWN = 7
} ExitanceRuntimeError;

typedef struct ExitanceRuntimeOptions {
  int32_t device_index; /* Vulkan physical device; -1 = prefer a discrete GPU */
  int32_t has_seed;     /* 0: the bake's seed; 1: `seed` */
  uint64_t seed;
  /* 0: keep the estimate per light layer (docs/runtime.md, "Light layers": 24 bytes per layer and
   * texel in each estimate kept); 1: keep none (edits that only scale lights then restart or are
   * estimated as a change). Set every field: the struct has no default. */
  int32_t light_layers_off;
} ExitanceRuntimeOptions;

typedef struct ExitanceRefreshReport {
  double milliseconds;        /* this call */
  uint64_t rays;              /* this call */
  uint32_t samples_added;     /* per texel, this call */
  uint32_t samples_per_texel; /* accumulated since the last edit */
  int32_t capped;             /* 1 when the sample cap is reached */
} ExitanceRefreshReport;

typedef struct ExitanceRuntimePageInfo {
  uint32_t width;
  uint32_t height;
} ExitanceRuntimePageInfo;

/* Opens a bundle bake wrote (manifest.json, scene.bin, ...) on a Vulkan device. options may be
 * NULL (defaults). On failure *out_runtime is NULL. */
ExitanceRuntimeError exitance_runtime_open(const char* bundle, const ExitanceRuntimeOptions* options,
                                           ExitanceRuntime** out_runtime);
/* Frees the runtime and its device resources. NULL is ignored. */
void exitance_runtime_release(ExitanceRuntime* runtime);

/* The error of this thread's most recent call, and its one-line message ("" when none). */
ExitanceRuntimeError exitance_runtime_last_error(void);
const char* exitance_runtime_last_error_message(void);

/* Applies edits given as EDITS.json text (docs/edits.md), all or nothing. Edits that only scale
 * lights (intensity, colour, emission, a constant sky) scale their light layers where the session
 * can (docs/runtime.md, "Light layers"), with no ray traced and every sample kept; other edits of
 * punctual lights are estimated as a change; the rest restart the accumulation. Texels show their
 * pre-edit value until the refreshed one is better (docs/runtime.md, "How a refresh works"). */
ExitanceRuntimeError exitance_runtime_apply_edits(ExitanceRuntime* runtime, const char* edits_json);

/* Adds samples to every texel within `budget_ms` milliseconds (0 = no time limit) and up to
 * `max_samples_per_texel` accumulated (0 = no cap); at least one of the two must be set.
 * out_report may be NULL. */
ExitanceRuntimeError exitance_runtime_refresh(ExitanceRuntime* runtime, double budget_ms, uint32_t max_samples_per_texel,
                                              ExitanceRefreshReport* out_report);

/* Estimated relMSE of the lightmap against its converged value (per-texel sample variances);
 * infinity before 2 samples. Reads the lightmap back from the device. */
ExitanceRuntimeError exitance_runtime_estimated_relative_mse(ExitanceRuntime* runtime, double* out_relative_mse);

uint32_t exitance_runtime_page_count(const ExitanceRuntime* runtime);
ExitanceRuntimeError exitance_runtime_page_info(const ExitanceRuntime* runtime, uint32_t page,
                                                ExitanceRuntimePageInfo* out_info);
/* Lightmap page `page` as it would be written (E/pi, gutters dilated): width x height RGB floats,
 * row 0 at the top, into out_rgb (3 * width * height floats; width and height must match). */
ExitanceRuntimeError exitance_runtime_read_page(ExitanceRuntime* runtime, uint32_t page, float* out_rgb, uint32_t width,
                                                uint32_t height);

/* One channel of page `page` as it would be written, width x height floats into out_values: any
 * channel of the bundle's pages ("R", "direct.G", "error.Y", ...), and for a bundle baked with
 * --directional sh1 the refreshed L1 layers "sh1.x.R" .. "sh1.z.B" (docs/bundle.md, "Directional
 * layers"), which an engine lighting normal maps reads with the refreshed E/pi. An unknown channel
 * is EXITANCE_RUNTIME_INVALID_ARGUMENT naming it. */
ExitanceRuntimeError exitance_runtime_read_page_channel(ExitanceRuntime* runtime, uint32_t page, const char* channel,
                                                        float* out_values, uint32_t width, uint32_t height);

/* Light probes as they show now, refreshed in the frames of exitance_runtime_refresh (docs/runtime.md
 * "Probes"): the bundle's probe grid in probes.bin's order (docs/bundle.md), 27 floats per probe, the
 * L2 SH of incident radiance (coefficient i, channel c at [i * 3 + c]; 0 for probes not in use).
 * out_count: the grid's probes, 0 when the bundle has none. `count` must equal it; out_sh holds
 * 27 * count floats. out_samples (may be NULL): the fewest refreshed samples of a probe since the
 * last edit that restarted them (an edit that only scales lights scales them and keeps every
 * sample). Reads the probes back from the device. */
ExitanceRuntimeError exitance_runtime_probe_count(const ExitanceRuntime* runtime, uint32_t* out_count);
ExitanceRuntimeError exitance_runtime_read_probes(ExitanceRuntime* runtime, float* out_sh, uint32_t count,
                                                  uint32_t* out_samples);
/* The share of each exitance_runtime_refresh call's time budget the probes get, in [0, 1] (default
 * 0.25); 0 refreshes no probe (each keeps showing what it shows). Outside [0, 1] or NaN:
 * EXITANCE_RUNTIME_INVALID_ARGUMENT, nothing changed. */
ExitanceRuntimeError exitance_runtime_set_probe_budget_share(ExitanceRuntime* runtime, double share);

/* Light subpaths in the refresh (docs/runtime.md "Light paths"): with on = 1, every pass from the
 * next exitance_runtime_refresh call on connects each texel path's vertices (and each refreshed
 * probe's) to a pool of subpaths traced from the lights and the sky, weighted by MIS: light that
 * enters through narrow openings (a door ajar) converges several times sooner, at about 1.6x a
 * plain sample's cost (bench/results/light-subpaths.md). on = 0 (the default) path traces. Samples
 * taken before keep theirs. subpaths_per_sample: the pool's size per texel sample, in (0, 64];
 * 0 takes the default, 1/16. on other than 0 or 1, or subpaths_per_sample negative, NaN or over
 * 64: EXITANCE_RUNTIME_INVALID_ARGUMENT, nothing changed. */
ExitanceRuntimeError exitance_runtime_set_light_paths(ExitanceRuntime* runtime, int32_t on, double subpaths_per_sample);

/* The sparse voxel octree's radiant exitance as the runtime shows it now (docs/runtime.md "Voxel
 * exitance"): per node of the bundle's svo.bin, in its order (breadth-first, formats/svo_format.md; the
 * loader (exitance_loader.h) reads the structure), 6 floats: front RGB then back RGB, M = pi L_o in
 * W/m^2 scene units, exactly what exitance_runtime_write_bundle would write into svo.bin (half
 * floats times its scale) from what the runtime shows (filtered where a denoise radius is set).
 * out_count: the octree's nodes, 0 when the bundle has no svo.bin. `count` must equal it; out_exitance
 * holds 6 * count floats. A read-back of the lightmap and a host pass over the texels (~0.1 s at 1 M
 * texels on the H200's host): not a per-frame call. */
ExitanceRuntimeError exitance_runtime_voxel_count(const ExitanceRuntime* runtime, uint32_t* out_count);
ExitanceRuntimeError exitance_runtime_read_voxel_exitance(ExitanceRuntime* runtime, float* out_exitance, uint32_t count);

/* The texture-space filter of the indirect light (docs/runtime.md "Filtered indirect light"): with a
 * radius of 1 to 16 texels, what read_page, read_page_channel, the page images and write_bundle show
 * has each texel's indirect light averaged over atlas neighbours on the same surface (on the device,
 * below a millisecond per million texels on an H200: bench/results/denoise.md); its direct light,
 * and what the refresh keeps and replaces, are unchanged. 0 (the default) turns it off. A radius
 * outside 0 to 16, or a radius > 0 on a bundle baked with --directional sh1:
 * EXITANCE_RUNTIME_INVALID_ARGUMENT, nothing changed. */
ExitanceRuntimeError exitance_runtime_set_denoise_radius(ExitanceRuntime* runtime, int32_t radius);

/* Writes the refreshed bundle (lightmaps, probes, voxel exitance, the edited scene.bin) to
 * `output_folder` atomically, as the runtime shows them (the probes as refreshed, where the runtime
 * refreshes them); the loader (exitance_loader.h) opens it. */
ExitanceRuntimeError exitance_runtime_write_bundle(ExitanceRuntime* runtime, const char* output_folder);

#ifdef __cplusplus
}
#endif

#endif /* EXITANCE_RUNTIME_H */
