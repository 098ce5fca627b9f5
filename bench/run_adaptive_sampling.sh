#!/usr/bin/env bash
# Equal-sample (and measured-time) relMSE of uniform against adaptive sampling on every sample scene,
# CPU backend: bench/results/adaptive-sampling.md. Usage: bench/run_adaptive_sampling.sh BUILD_DIR OUT.csv
set -euo pipefail
build=${1:-build}
out=${2:-adaptive-sampling.csv}
samples=$build/samples
bench=$build/bench/bench_time_to_error
: > "$out"
run() {  # name, extra args
  local name=$1; shift
  "$bench" "$samples/$name.gltf" --integrators path,adaptive --min-spp 64 --max-spp 512 --csv "$out.part" "$@"
  if [ -s "$out" ]; then tail -n +2 "$out.part" >> "$out"; else cat "$out.part" > "$out"; fi
  rm -f "$out.part"
}
run cornell_room --texel-density 4 --reference-spp 16384
run ajar_room --texel-density 8 --reference-spp 16384
run thin_walls --texel-density 8 --reference-spp 8192
run courtyard --texel-density 2 --reference-spp 4096 --sky 0.5,0.6,0.8
run building --texel-density 0.5 --reference-spp 4096
