#!/usr/bin/env bash
# run_fuzzers.sh [SECONDS]: builds the libFuzzer targets with clang++ in build-fuzz/, seeds a corpus
# with valid files from the writers (and, for the glTF importer, the hostile files of tests/badinput),
# and runs each fuzzer (probes.bin, svo.bin, scene.bin, manifest.json, EDITS.json, glTF/GLB) for SECONDS (default 30); EXITANCE_FUZZERS="scene" runs only the ones named. Exits non-zero if any fuzzer finds a crash, a sanitizer error, an escaped
# exception or a timeout; the failing input is left in build-fuzz/artifacts/.
# Needs clang and libclang-rt-14-dev (scripts/install-deps.sh).
set -euo pipefail
seconds="${1:-30}"
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="$root/build-fuzz"
generator=()
if command -v ninja >/dev/null; then generator=(-G Ninja); fi

cmake -S "$root/tests/fuzz" -B "$build" "${generator[@]}" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j"$(nproc)"
rm -rf "$build/seeds"
"$build/write_fuzz_seeds" "$build/seeds"
mkdir -p "$build/seeds/gltf"
# Inputs that once failed a fuzzer: every run replays them first (tests/fuzz/regressions/READER/).
for dir in "$root"/tests/fuzz/regressions/*/; do
  mkdir -p "$build/seeds/$(basename "$dir")" && cp "$dir"* "$build/seeds/$(basename "$dir")/"
done
cp "$root"/tests/badinput/hostile/*.gltf "$root"/tests/badinput/hostile/*.glb "$build/seeds/gltf/" 2>/dev/null || true
mkdir -p "$build/artifacts"

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
failed=()
for reader in ${EXITANCE_FUZZERS:-probes svo scene manifest edits gltf}; do
  corpus="$build/corpus/$reader"  # kept between runs so each run starts where the last one stopped
  mkdir -p "$corpus"
  options=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1
           -artifact_prefix="$build/artifacts/$reader-")
  if [ "$reader" = manifest ]; then options+=(-dict="$root/tests/fuzz/manifest.dict"); fi
  echo "== fuzz_$reader for ${seconds}s"
  if ! "$build/fuzz_$reader" "${options[@]}" "$corpus" "$build/seeds/$reader" >"$build/fuzz_$reader.log" 2>&1; then
    tail -n 60 "$build/fuzz_$reader.log"
    failed+=("$reader")
  else
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$build/fuzz_$reader.log" || true
  fi
done
if [ "${#failed[@]}" -ne 0 ]; then
  echo "fuzzers failed: ${failed[*]} (inputs in $build/artifacts/)"
  exit 1
fi
echo "fuzzers ran clean: ${EXITANCE_FUZZERS:-probes svo scene manifest edits gltf}, ${seconds}s each"
