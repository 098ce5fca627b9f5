#!/usr/bin/env bash
# Rays per second of the CPU reference (Embree) on the >= 200 k-triangle building, via `bake --json`.
#   bash bench/reference_throughput.sh [BUILD_DIR] [TEXEL_DENSITY] [SPP]
set -euo pipefail
build="${1:-build}"
density="${2:-2}"
spp="${3:-16}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
"$build/bake/bake" "$build/samples/building.gltf" -o "$out/building.bake" --backend cpu \
  --texel-density "$density" --spp "$spp" --json 2>/dev/null |
  python3 -c '
import json, sys
r = json.load(sys.stdin)
print(f"triangles {r[\"triangles\"]}, live texels {r[\"live_texels\"]}, spp {r[\"samples_per_texel\"][\"mean\"]:.0f}, "
      f"rays {r[\"rays\"]}, lighting {r[\"seconds\"][\"lighting\"]:.2f} s, {r[\"rays_per_second\"] / 1e6:.2f} Mrays/s, "
      f"device: {r[\"device\"]}")'
