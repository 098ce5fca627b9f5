#!/usr/bin/env bash
# Rays per second of the CPU reference (Embree) on the >= 200 k-triangle building, via `bake --json`.
#   bash bench/reference_throughput.sh [BUILD_DIR] [TEXEL_DENSITY] [SPP]
set -euo pipefail
build="${1:-build}"
density="${2:-2}"
spp="${3:-16}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
"$build/bake/bake" "$build/samples/building.gltf" -o "$out/building.bake" --backend cpu --no-cache \
  --texel-density "$density" --spp "$spp" --json 2>/dev/null >"$out/report.json"
python3 - "$out/report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
print("triangles %d, live texels %d, spp %.0f, rays %d, lighting %.2f s, %.2f Mrays/s, device: %s" % (
    r["triangles"], r["live_texels"], r["samples_per_texel"]["mean"], r["rays"], r["seconds"]["lighting"],
    r["rays_per_second"] / 1e6, r["device"]))
PY
