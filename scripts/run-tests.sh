#!/usr/bin/env bash
# Builds Release and runs the whole CTest suite, then builds with ASan+UBSan and reruns the
# bad-input and stress tests under the sanitizers. Assumes scripts/install-deps.sh has run.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"

cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DEXITANCE_SANITIZE=ON
# Only what the sanitizer run executes: the bake command and the unit/stress test programs.
cmake --build build-asan -j"$jobs" --target bake stress_tests geometry_warning_tests layout_tests gltf_import_tests \
  pipeline_tests
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir build-asan --output-on-failure -j"$jobs" -L "badinput|stress|unit"
