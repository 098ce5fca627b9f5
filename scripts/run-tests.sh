#!/usr/bin/env bash
# Builds Release and runs the whole CTest suite but the bad-input label, reruns the CPU-reference
# tests on Embree's SSE4.2 kernels, then builds with clang and ASan+UBSan and runs the bad-input,
# stress and unit tests (formats and loader included) under the sanitizers, then fuzzes the
# probes.bin / svo.bin / scene.bin / manifest.json / EDITS.json / glTF readers for 6 s each. The
# bad-input label runs once, under the sanitizers: the same files, exit codes and messages as a
# Release run, with memory and UB checks on top (running it twice cost CI ~75 s of its 30 min).
# Assumes scripts/install-deps.sh has run.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"
# Compiler cache (ccache, from scripts/install-deps.sh) for every build below, the fuzzers' included:
# a rerun on the same machine recompiles only what changed. Keyed on paths relative to this
# checkout (and not on the build folder), so every clone shares one cache (~/.cache/ccache).
if command -v ccache > /dev/null; then
  export CMAKE_C_COMPILER_LAUNCHER=ccache CMAKE_CXX_COMPILER_LAUNCHER=ccache
  export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true CCACHE_MAXSIZE="${CCACHE_MAXSIZE:-8G}"
fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
# Every test has its own TIMEOUT (tests/CMakeLists.txt); --timeout is the backstop for one without.
ctest_run=(ctest --output-on-failure -j"$jobs" --timeout 900)
"${ctest_run[@]}" --test-dir build -LE badinput

# Embree picks its kernels per CPU (SSE4.2, AVX2, AVX-512), and they need not report the same one of
# several equidistant hits: rerun the CPU-reference tests (pipeline tests included) on the SSE4.2
# kernels, so a result that depends on the CPU fails on any machine. Not the Vulkan backend's tests
# (crosschecks, or the stress tests' vulkan* parameters: 18 tests, ~130 s of CI's test time): they
# trace the runtime's own BVH on lavapipe, not Embree's kernels.
isa=$(EXITANCE_EMBREE_CONFIG=isa=sse4.2,verbose=1 build/tests/geometry_warning_tests --gtest_filter='*CleanRoom*' |
      sed -n '/^  Config/,/Targets/s/^ *ISA *: *//p')  # the ISA Embree selected, from its verbose report
if ! grep -q 'SSE4\.2' <<<"$isa" || grep -q AVX <<<"$isa"; then
  echo "EXITANCE_EMBREE_CONFIG=isa=sse4.2 did not select Embree's SSE4.2 kernels (ISA: '$isa')"; exit 1
fi
EXITANCE_EMBREE_CONFIG=isa=sse4.2 "${ctest_run[@]}" --test-dir build -L "analytic|stress|unit" -E "/vulkan"

# The sanitizer build uses clang, so it also checks that everything the unit, stress and bad-input
# tests run compiles with clang (one build instead of two: a separate clang Release build plus a
# gcc ASan build took 13.5 min of CI's 30 on 2 cores in the last clean-clone run; this one built in
# 6.1 min here). -O1 with line tables only: what ASan's stack traces need.
sanitize_flags="-O1 -gline-tables-only -DNDEBUG"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DEXITANCE_SANITIZE=ON \
  -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$sanitize_flags" -DCMAKE_C_FLAGS_RELWITHDEBINFO="$sanitize_flags"
# Only what the sanitizer run executes: the bake command and the unit/stress test programs.
cmake --build build-asan -j"$jobs" --target bake stress_tests geometry_warning_tests layout_tests gltf_import_tests \
  pipeline_tests formats_tests huge_page_operator_new_tests exitance_loader_sample make_loader_test_bundle spherical_harmonics_tests \
  svo_exitance_tests svo_build_tests probe_placement_tests bundle_end_to_end_tests common_math_tests path_sampler_tests environment_map_tests \
  lighting_scene_edit_tests scene_edits_tests radiance_vdb_tests scene_file_tests exitance-relight \
  exitance_runtime exitance_loader bundle_cache_tests lightmap_uv_generation_tests adaptive_sampling_plan_tests guiding_auto_strategy_tests \
  stage_cache_keys_tests texture_sampling_tests per_bounce_budget_tests unocclude_tests \
  seam_detection_tests view_materials_tests bake_guiding_options_tests work_share_split_tests bvh4_spatial_split_tests light_layer_pages_tests indirect_denoise_tests \
  exitance-view
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
"${ctest_run[@]}" --test-dir build-asan -L "badinput|stress|unit"

# libFuzzer (clang) on the on-disk readers; non-zero on any crash or sanitizer report.
bash tests/fuzz/run_fuzzers.sh 6
