#!/usr/bin/env bash
# The cost of bake --directional sh1 (bench/results/directional-sh1.md): lighting-stage seconds and the
# E/pi noise relMSE at equal samples per texel, off against sh1 (the defensive first-continuation
# mixture changes the E/pi variance).
#   bench/run_directional_sh1.sh [BUILD_DIR] [OUT_DIR]
# Environment: SCENES (default "cornell_room courtyard"), SPP (default 64), DENSITY (16).
# Each (scene, mode): two CPU bakes, seeds 1 and 2, --adaptive off, no probes or voxels. Noise relMSE =
# mean over fully covered traced texels and channels of (a - b)^2 / (2 (r^2 + 1e-3)) (both modes are
# unbiased, so this is their whole error), r = the off run of seed 1 (only a weight, the same for both).
# Seconds: the lighting stage of seed 1 and seed 2.
set -euo pipefail
BUILD=${1:-build}
OUT=${2:-/tmp/exitance-directional-sh1}
SCENES=${SCENES:-cornell_room courtyard}
SPP=${SPP:-64}
DENSITY=${DENSITY:-16}
BAKE=$BUILD/bake/bake
COMPARE=$BUILD/bench/bench_compare_lightmap_pages
mkdir -p "$OUT"
[ -f "$BUILD/samples/cornell_room.gltf" ] || "$BUILD/samples/generate_samples" "$BUILD/samples" >/dev/null
lighting_seconds() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['stats']['seconds']['lighting'])" "$1/manifest.json"; }
echo "scene,directional,spp,seconds_seed1,seconds_seed2,noise_rel_mse"
for scene in $SCENES; do
  for mode in off sh1; do
    extra=()
    [ "$mode" = sh1 ] && extra=(--directional sh1)
    for seed in 1 2; do
      "$BAKE" "$BUILD/samples/$scene.gltf" -o "$OUT/$scene-$mode-$seed" --spp "$SPP" --seed "$seed" "${extra[@]}" \
        --adaptive off --texel-density "$DENSITY" --probes none --voxel-resolution none --no-cache --backend cpu \
        >/dev/null 2>&1
    done
  done
  weight=$OUT/$scene-off-1/lightmap-0.exr
  for mode in off sh1; do
    run=$OUT/$scene-$mode
    noise=$("$COMPARE" "$weight" "$weight" --pair "$run-1/lightmap-0.exr" "$run-2/lightmap-0.exr" | sed -n 's/.*noise_rel_mse //p')
    echo "$scene,$mode,$SPP,$(lighting_seconds "$run-1"),$(lighting_seconds "$run-2"),$noise"
  done
done
