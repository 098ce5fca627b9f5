#!/usr/bin/env bash
# Soak test for issue 31 (Vulkan work hanging on lavapipe): runs the Vulkan tests and the
# quickstart's relight over and over on lavapipe with the machine loaded, and with Mesa's shader
# cache emptied now and then (a cold cache is what a fresh CI machine has: lavapipe then compiles
# each kernel with LLVM at its first dispatch, 20-60 s for all of them on 2 loaded cores).
# A run that exits non-zero or passes its limit is counted, and its output kept.
#
#   bash bench/lavapipe_soak.sh [BUILD_DIR] [TEST_ROUNDS] [RELIGHT_RUNS] [TEST_REGEX]
#
# Defaults: build, 20 rounds of `ctest -L crosscheck` plus the stress and unit tests that run on
# Vulkan, 50 relights of the quickstart bundle (baked first if missing). Load: one busy loop per
# core beside the tests (stress-ng when installed). Every 5th round and 10th relight starts from an
# empty shader cache (MESA_SHADER_CACHE_DIR points into the work folder, never at the user's cache).
# Prints a summary table (markdown) at the end; bench/results/lavapipe-soak.md keeps the figures.
set -uo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
rounds="${2:-20}"
relights="${3:-50}"
regex="${4:-}"
work="$(mktemp -d /tmp/exitance-soak.XXXXXX)"
export MESA_SHADER_CACHE_DIR="$work/mesa-cache"
export EXITANCE_VULKAN_VALIDATION=1
cores="$(nproc)"

load_pids=()
if command -v stress-ng > /dev/null; then
  stress-ng --cpu "$cores" --quiet & load_pids+=($!)
else
  for _ in $(seq "$cores"); do (while :; do :; done) & load_pids+=($!); done
fi
trap 'kill "${load_pids[@]}" 2> /dev/null' EXIT

bundle="$build/cornell_room.bake"
if [ ! -f "$bundle/scene.bin" ]; then
  "$build/bake/bake" "$build/samples/cornell_room.gltf" -o "$bundle" --texel-density 16 --spp 128 2> /dev/null
fi

test_failures=0 test_seconds_max=0
selection=(-L crosscheck)
[ -n "$regex" ] && selection=(-R "$regex")
for round in $(seq "$rounds"); do
  [ $((round % 5)) -eq 1 ] && rm -rf "$MESA_SHADER_CACHE_DIR"
  start=$(date +%s)
  if ! ctest --test-dir "$build" -j"$cores" --timeout 900 "${selection[@]}" > "$work/ctest-$round.log" 2>&1; then
    test_failures=$((test_failures + 1))
    echo "round $round: failed (log $work/ctest-$round.log)"
    grep -E "Failed|Timeout|Not Run" "$work/ctest-$round.log" | head -20
  fi
  if [ -z "$regex" ]; then  # the Vulkan stress cases and the Vulkan unit programs too
    ctest --test-dir "$build" -j"$cores" --timeout 900 -R "stress_tests.*vulkan|vulkan_host" >> "$work/ctest-$round.log" 2>&1 ||
      { test_failures=$((test_failures + 1)); echo "round $round: stress/unit failed (log $work/ctest-$round.log)"; }
  fi
  seconds=$(( $(date +%s) - start ))
  [ "$seconds" -gt "$test_seconds_max" ] && test_seconds_max=$seconds
  echo "round $round: ${seconds} s"
done

relight_failures=0 relight_seconds_max=0
for run in $(seq "$relights"); do
  [ $((run % 10)) -eq 1 ] && rm -rf "$MESA_SHADER_CACHE_DIR"
  start=$(date +%s.%N)
  timeout 600 "$build/runtime/exitance-relight" "$bundle" -o "$work/relit.bake" --spp 8 > "$work/relight-$run.log" 2>&1
  status=$?
  seconds=$(echo "$(date +%s.%N) - $start" | bc)
  if [ "$status" -ne 0 ]; then
    relight_failures=$((relight_failures + 1))
    echo "relight $run: exit $status after $seconds s: $(tail -1 "$work/relight-$run.log")"
  fi
  relight_seconds_max=$(echo "if ($seconds > $relight_seconds_max) $seconds else $relight_seconds_max" | bc)
  rm -rf "$work/relit.bake"
done

echo
echo "| what | runs | failed or hung | longest (s) |"
echo "|---|---|---|---|"
what="ctest ${selection[*]}"
[ -z "$regex" ] && what="$what, then -R 'stress_tests.*vulkan|vulkan_host'"
echo "| $what | $rounds | $test_failures | $test_seconds_max |"
echo "| exitance-relight cornell_room --spp 8 | $relights | $relight_failures | $relight_seconds_max |"
echo "(load: $cores busy loops; logs in $work)"
[ "$test_failures" -eq 0 ] && [ "$relight_failures" -eq 0 ]
