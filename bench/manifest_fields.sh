# Shell helpers the bench scripts source: figures read from a bundle's manifest.json.
#   . "$(dirname "$0")/manifest_fields.sh"

# lighting_seconds BUNDLE: the lighting stage's time (stats.seconds.lighting).
lighting_seconds() {
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['stats']['seconds']['lighting'])" "$1/manifest.json"
}
