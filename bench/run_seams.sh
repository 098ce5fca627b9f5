#!/usr/bin/env bash
# Seam stitching (bench/results/seams.md): the sphere over a floor (generated UVs, 2 charts on the
# sphere) baked on the CPU at two densities and three sample counts, under a sky alone and with a
# sun; prints stats.seams of each bake. Usage: bench/run_seams.sh [BUILD_DIR] (default build-rel).
set -euo pipefail
build=${1:-build-rel}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$build/bench/bench_write_seam_sphere" "$work/sky.gltf" 48 24
"$build/bench/bench_write_seam_sphere" "$work/sun.gltf" 48 24 sun
echo "| light | density | spp | edges | texels adjusted | before | after | before/after | texel error.Y | seams s | lighting s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for light in sky sun; do
  sky=$([ "$light" = sky ] && echo 1,1,1 || echo 0.3,0.35,0.45)
  for density in 12 32; do
    for spp in 16 64 256 1024; do
      "$build/bake/bake" "$work/$light.gltf" -o "$work/out.bake" --sky "$sky" --texel-density "$density" --spp "$spp" \
        --seed 1 --backend cpu --probes none --voxel-resolution none --no-cache --json 2>/dev/null |
        python3 -c "
import json, sys
r = json.load(sys.stdin); s = r['seams']
print('| $light | $density | $spp | %d | %d | %.5f | %.5f | %.1f | %.5f | %.3f | %.2f |' % (s['edges'], s['texels_adjusted'],
      s['discontinuity_before'], s['discontinuity_after'], s['discontinuity_before'] / s['discontinuity_after'],
      s['texel_relative_error'], s['seconds'], r['seconds']['lighting']))"
    done
  done
done
