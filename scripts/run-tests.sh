#!/usr/bin/env bash
# Builds Release and runs the whole CTest suite, then builds with ASan+UBSan and reruns the
# bad-input, stress and unit tests (formats and loader included) under the sanitizers, then fuzzes
# the probes.bin / svo.bin / manifest.json readers for 20 s each. Assumes scripts/install-deps.sh has run.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"

cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DEXITANCE_SANITIZE=ON
# Only what the sanitizer run executes: the bake command and the unit/stress test programs.
cmake --build build-asan -j"$jobs" --target bake stress_tests geometry_warning_tests layout_tests gltf_import_tests \
  pipeline_tests formats_tests exitance_loader_sample make_loader_test_bundle spherical_harmonics_tests \
  svo_exitance_tests svo_build_tests probe_placement_tests bundle_end_to_end_tests
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir build-asan --output-on-failure -j"$jobs" -L "badinput|stress|unit"

# libFuzzer (clang) on the on-disk readers; non-zero on any crash or sanitizer report.
bash tests/fuzz/run_fuzzers.sh 20
