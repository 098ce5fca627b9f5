#!/usr/bin/env bash
# The path-traced references beside the README's "Pictures": for each bundle written by
# scripts/make_readme_pictures.sh's settings (with --preview), the automatic view's camera is read from
# the manifest's `preview` block and the same view is path traced by `exitance-view --path-traced`
# into docs/images/<scene>-auto-reference.png. Needs a Vulkan device (a GPU; lavapipe works but takes
# hours at these sample counts). Run by hand; CI does not regenerate the pictures.
#   scripts/make_readme_references.sh VIEW_BINARY BUNDLE_DIR [SPP]
#   (BUNDLE_DIR holds cornell_room.bake ... building.bake; default 16384 spp, 4x that for the ajar room)
set -euo pipefail

root="$(cd "$(dirname "$0")/.." && pwd)"
view="$1"
bundles="$2"
spp="${3:-16384}"
for name in cornell_room ajar_room thin_walls courtyard building; do
  camera=$(python3 - "$bundles/$name.bake/manifest.json" <<'PY'
import json, sys
v = json.load(open(sys.argv[1]))["preview"]["views"][0]
f = lambda a: ",".join(repr(x) for x in a)
print("--look-from", f(v["look_from"]), "--look-at", f(v["look_at"]), "--up", f(v["up"]),
      "--yfov", repr(v["yfov"]), "--size", "%d,%d" % (v["width"], v["height"]))
PY
)
  n=$spp
  [ "$name" = ajar_room ] && n=$((spp * 4))  # lit only through a door gap
  # shellcheck disable=SC2086
  "$view" "$bundles/$name.bake" $camera --path-traced --spp "$n" --seed 1 -o "$root/docs/images/$name-auto-reference.png"
done
