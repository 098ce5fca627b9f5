#!/usr/bin/env bash
# exitance-view render time on the building (bench/results/view.md): bakes samples/building.gltf at a
# modest density once (or reuses BUNDLE), then renders one interior view at 512x512 and 1920x1080
# (lightmap mode, one ray per pixel, and --aa 2), REPEATS times each, with all hardware threads and
# with one. Prints the exitance-view summary lines (open / render / write seconds). With
# VIEW_BENCH_PNG=FILE.png it also writes the 960x540 --aa 2 picture of that view.
# Usage: bench/view_bench.sh BUILD_DIR [BUNDLE] [REPEATS]
set -euo pipefail
build=${1:?usage: bench/view_bench.sh BUILD_DIR [BUNDLE] [REPEATS]}
bundle=${2:-/tmp/exitance-view-bench/building.bake}
repeats=${3:-3}
view=$build/runtime/exitance-view
out=$(mktemp -d /tmp/exitance-view-bench-out.XXXXXX)
trap 'rm -rf "$out"' EXIT
if [ ! -f "$bundle/scene.bin" ]; then
  mkdir -p "$(dirname "$bundle")"
  /usr/bin/time -f "bake: %e s wall, %M KB peak" "$build/bake/bake" "$build/samples/building.gltf" -o "$bundle" \
    --texel-density 8 --spp 16 --no-cache
fi
# Ground floor, room (0, 0): from its north-west corner towards the south-east one.
camera=(--look-from 0.5,1.6,0.5 --look-at 5.0,0.9,5.0 --yfov 1.2)
for size in 512 1920,1080; do
  for aa in 1 2; do
    for threads in 0 1; do
      for ((i = 1; i <= repeats; ++i)); do
        extra=()
        [ "$threads" = 0 ] || extra=(--threads "$threads")
        echo -n "size $size aa $aa threads ${threads/0/all}: "
        "$view" "$bundle" "${camera[@]}" --size "$size" --aa "$aa" "${extra[@]}" -o "$out/view.exr" 2>&1
      done
    done
  done
done
# The picture results/view.md shows.
if [ -n "${VIEW_BENCH_PNG:-}" ]; then
  "$view" "$bundle" "${camera[@]}" --size 960,540 --aa 2 -o "$VIEW_BENCH_PNG" 2>&1
fi
