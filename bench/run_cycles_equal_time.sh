#!/usr/bin/env bash
# Equal-time error of `bake` against Blender's Cycles bake on the Cornell room (bench/results/cycles-equal-time.md).
#   bench/run_cycles_equal_time.sh [BUILD_DIR] [OUT_DIR]
# Needs blender (Debian: apt-get install blender python3-numpy). Environment knobs: DENSITY (texels per
# unit, default 16), SAMPLES (Cycles samples per texel, default "16 64 256"), REFERENCE_SPP (default 2048).
#
# For each Cycles sample count: two Cycles bakes with seeds 1 and 2 give the time T (the bake call:
# sync, BVH, tracing); then `bake --time T` with the same two seeds for each of our configurations.
# Error of one run, from its noise alone (unbiased, needs no converged reference):
#   noise relMSE = mean over fully covered traced texels and channels of (a - b)^2 / (2 (r^2 + 1e-3))
# for the two seeds a, b, r = the reference (a --spp REFERENCE_SPP bake). The relMSE of seed 1
# against the reference adds both renderers' bias and the reference's noise.
set -euo pipefail
BUILD=${1:-build}
OUT=${2:-/tmp/exitance-cycles}
DENSITY=${DENSITY:-16}
SAMPLES=${SAMPLES:-16 64 256}
REFERENCE_SPP=${REFERENCE_SPP:-2048}
HERE=$(cd "$(dirname "$0")" && pwd)
BAKE=$BUILD/bake/bake
COMPARE=$BUILD/bench/bench_compare_lightmap_pages
mkdir -p "$OUT"
[ -f "$BUILD/samples/cornell_room.gltf" ] || "$BUILD/samples/generate_samples" "$BUILD/samples" >/dev/null
SCENE=$BUILD/samples/cornell_room.gltf
COMMON=(--texel-density "$DENSITY" --probes none --voxel-resolution none --no-cache --backend cpu)

# shellcheck source=bench/manifest_fields.sh
. "$(cd "$(dirname "$0")" && pwd)/manifest_fields.sh"

if [ ! -f "$OUT/reference/manifest.json" ]; then
  "$BAKE" "$SCENE" -o "$OUT/reference" --spp "$REFERENCE_SPP" --seed 99 "${COMMON[@]}" >/dev/null 2>&1
fi
if [ ! -f "$OUT/reference2/manifest.json" ]; then
  "$BAKE" "$SCENE" -o "$OUT/reference2" --spp "$REFERENCE_SPP" --seed 98 "${COMMON[@]}" >/dev/null 2>&1
fi
PAGE=$OUT/reference/lightmap-0.exr
# The reference's own noise (relMSE of one reference run), from two seeds: vs_reference minus it is a
# run's whole error, noise and bias, against the converged answer.
reference_noise=$("$COMPARE" "$PAGE" "$PAGE" --pair "$PAGE" "$OUT/reference2/lightmap-0.exr" | sed -n 's/.*noise_rel_mse //p')
echo "# reference noise relMSE $reference_noise"
echo "renderer,config,cycles_samples,seconds_seed1,seconds_seed2,noise_rel_mse,rel_mse_vs_reference,mean_ratio"
for n in $SAMPLES; do
  times=()
  for seed in 1 2; do
    t=$(blender -b --python-exit-code 1 -P "$HERE/cycles/cycles_bake.py" -- "$SCENE" "$OUT/reference" \
          "$OUT/cycles-$n-$seed" "$n" 2 0,0,0 "$seed" 2>/dev/null | sed -n 's/^cycles_bake_seconds //p')
    times+=("$t")
  done
  noise=$("$COMPARE" "$PAGE" "$PAGE" --pair "$OUT/cycles-$n-1-0.pfm" "$OUT/cycles-$n-2-0.pfm" | sed -n 's/.*noise_rel_mse //p')
  read -r vs ratio < <("$COMPARE" "$PAGE" "$PAGE" "$OUT/cycles-$n-1-0.pfm" | sed -n 's/.*rel_mse \([^ ]*\) mean_ratio \(.*\)/\1 \2/p')
  echo "cycles,path,$n,${times[0]},${times[1]},$noise,$vs,$ratio"
  budget=$(python3 -c "print(min(float('${times[0]}'), float('${times[1]}')))")
  for config in "uniform-independent:--adaptive off --sampler independent" "uniform:--adaptive off" \
                "adaptive:--adaptive on" "adaptive-guided:--adaptive on --guiding grid" "bounces:--integrator bounces"; do
    name=${config%%:*}
    read -r -a flags <<<"${config#*:}"
    secs=()
    for seed in 1 2; do
      "$BAKE" "$SCENE" -o "$OUT/$name-$n-$seed" --time "$budget" --seed "$seed" "${flags[@]}" "${COMMON[@]}" >/dev/null 2>&1
      secs+=("$(lighting_seconds "$OUT/$name-$n-$seed")")
    done
    noise=$("$COMPARE" "$PAGE" "$PAGE" --pair "$OUT/$name-$n-1/lightmap-0.exr" "$OUT/$name-$n-2/lightmap-0.exr" | sed -n 's/.*noise_rel_mse //p')
    read -r vs ratio < <("$COMPARE" "$PAGE" "$PAGE" "$OUT/$name-$n-1/lightmap-0.exr" | sed -n 's/.*rel_mse \([^ ]*\) mean_ratio \(.*\)/\1 \2/p')
    echo "exitance,$name,$n,${secs[0]},${secs[1]},$noise,$vs,$ratio"
  done
done
