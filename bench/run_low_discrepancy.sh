#!/usr/bin/env bash
# Low-discrepancy (Owen-scrambled Sobol) against independent random numbers, per scene, at equal
# samples per texel (bench/results/low-discrepancy.md).
#   bench/run_low_discrepancy.sh [BUILD_DIR] [OUT_DIR]
# Environment: SCENES (default "cornell_room ajar_room courtyard"), SPP (default "16 64 256"), DENSITY (16).
# Each (scene, sampler, spp): two bakes with seeds 1 and 2, uniform sampling, CPU backend, no probes or
# voxels. Noise relMSE = mean over fully covered traced texels and channels of (a - b)^2 / (2 (r^2 + 1e-3)),
# the relMSE of one run from its noise alone (both samplers are unbiased), with r = the largest Sobol
# run of seed 1 (only a weight, the same for both samplers). Seconds: the lighting stage of seed 1.
set -euo pipefail
BUILD=${1:-build}
OUT=${2:-/tmp/exitance-low-discrepancy}
SCENES=${SCENES:-cornell_room ajar_room courtyard}
SPP=${SPP:-16 64 256}
DENSITY=${DENSITY:-16}
BAKE=$BUILD/bake/bake
COMPARE=$BUILD/bench/bench_compare_lightmap_pages
mkdir -p "$OUT"
[ -f "$BUILD/samples/cornell_room.gltf" ] || "$BUILD/samples/generate_samples" "$BUILD/samples" >/dev/null
# shellcheck source=bench/manifest_fields.sh
. "$(cd "$(dirname "$0")" && pwd)/manifest_fields.sh"
largest=${SPP##* }
echo "scene,sampler,spp,seconds,noise_rel_mse"
for scene in $SCENES; do
  for sampler in sobol independent; do
    for spp in $SPP; do
      for seed in 1 2; do
        "$BAKE" "$BUILD/samples/$scene.gltf" -o "$OUT/$scene-$sampler-$spp-$seed" --spp "$spp" --seed "$seed" \
          --sampler "$sampler" --adaptive off --texel-density "$DENSITY" --probes none --voxel-resolution none \
          --no-cache --backend cpu >/dev/null 2>&1
      done
    done
  done
  weight=$OUT/$scene-sobol-$largest-1/lightmap-0.exr
  for sampler in sobol independent; do
    for spp in $SPP; do
      run=$OUT/$scene-$sampler-$spp
      noise=$("$COMPARE" "$weight" "$weight" --pair "$run-1/lightmap-0.exr" "$run-2/lightmap-0.exr" | sed -n 's/.*noise_rel_mse //p')
      echo "$scene,$sampler,$spp,$(lighting_seconds "$run-1"),$noise"
    done
  done
done
