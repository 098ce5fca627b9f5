#!/usr/bin/env bash
# The README's "Pictures": bakes each sample scene at modest settings with `bake --preview` and copies
# its preview views to docs/images/<scene>-<view>.png. Run by hand when the pictures should change
# (CI does not regenerate them); commit the PNGs it writes.
#   scripts/make_readme_pictures.sh [BUILD_DIR] [SIZE] [BUNDLE_DIR]
#   (default: build, 384 pixels wide; BUNDLE_DIR keeps the bundles for make_readme_references.sh)
# Needs the `bake` and `sample_scenes` targets (built here). CPU backend: runs on any machine.
set -euo pipefail

root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-build}"
size="${2:-384}"
case "$build" in /*) ;; *) build="$root/$build" ;; esac
ninja -C "$build" bake sample_scenes >/dev/null
images="$root/docs/images"
mkdir -p "$images"
if [ -n "${3:-}" ]; then
  work="$3"
  mkdir -p "$work"
else
  work="$(mktemp -d)"
  trap 'rm -rf "$work"' EXIT
fi

# bake_sample NAME [bake options...]: bakes build/samples/NAME.gltf and copies its views.
bake_sample() {
  local name="$1"
  shift
  local start=$SECONDS
  "$build/bake/bake" "$build/samples/$name.gltf" -o "$work/$name.bake" --no-cache --backend cpu \
    --probe-spp 128 --preview-size "$size" "$@"
  for view in "$work/$name.bake"/preview/view-*.png; do
    local file="$name-$(basename "$view" | sed 's/^view-//')"
    cp "$view" "$images/$file"
    echo "$file: $(stat -c %s "$images/$file") bytes ($((SECONDS - start)) s)"
  done
}

# Modest densities and samples (a few seconds each on 2 cores; the ajar room, lit through a door gap,
# needs more samples to be legible); the courtyard under its sky.
bake_sample cornell_room --texel-density 8 --spp 128
bake_sample ajar_room --texel-density 4 --spp 4096
bake_sample thin_walls --texel-density 8 --spp 64
bake_sample courtyard --texel-density 4 --spp 64 --sky 0.5,0.6,0.8
bake_sample building --texel-density 1 --spp 32
du -ch "$images"/*.png | tail -1
