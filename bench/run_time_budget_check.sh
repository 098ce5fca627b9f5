#!/usr/bin/env bash
# How closely `bake --time` holds its budget, two bake executables alternated (the machine is shared,
# so before/after runs interleave): bench/results/per-bounce-budget.md.
#   bench/run_time_budget_check.sh BEFORE_BAKE AFTER_BAKE [REPEATS]
# Needs the sample scenes (build/samples/generate_samples build/samples). Per run it prints the
# manifest's stats.seconds.lighting and .probes, their sum against the budget, and the lighting
# against what the probes left it (the lighting stage's own budget), plus any --time warning.
# Scenes: the open city at --texel-density 2 --time 20 and the Cornell room --time 5 in the
# per-bounce mode (the CPU default), and the Cornell room --time 5 path traced.
set -euo pipefail
BEFORE=$1
AFTER=$2
REPEATS=${3:-2}
SAMPLES=${SAMPLES:-build/samples}
OUT=$(mktemp -d /tmp/time-budget-check.XXXXXX)
run() {  # label executable budget scene-and-options...
  local label=$1 bake=$2 budget=$3
  shift 3
  "$bake" "$@" --time "$budget" --no-cache --json -o "$OUT/bundle" >"$OUT/report.json" 2>"$OUT/stderr"
  python3 - "$label" "$budget" "$OUT/report.json" <<'PY'
import json, sys
label, budget, path = sys.argv[1], float(sys.argv[2]), sys.argv[3]
report = json.load(open(path))
s = report["seconds"]
lighting, probes = s["lighting"], s.get("probes", 0.0)
print(f"{label:24s} lighting {lighting:7.3f} probes {probes:6.3f} sum {lighting + probes:7.3f} of {budget:5.1f} "
      f"({(lighting + probes) / budget * 100:6.2f} %)  lighting/(budget - probes) {lighting / (budget - probes) * 100:6.2f} %  "
      f"samples per texel {report['samples_per_texel']}")
PY
  grep -h "warning: --time" "$OUT/stderr" || true
}
uptime
for _ in $(seq "$REPEATS"); do
  run "city bounces before" "$BEFORE" 20 "$SAMPLES/open_city.gltf" --texel-density 2 --sky 0.5,0.6,0.8
  run "city bounces after" "$AFTER" 20 "$SAMPLES/open_city.gltf" --texel-density 2 --sky 0.5,0.6,0.8
done
for _ in $(seq "$REPEATS"); do
  run "cornell bounces before" "$BEFORE" 5 "$SAMPLES/cornell_room.gltf"
  run "cornell bounces after" "$AFTER" 5 "$SAMPLES/cornell_room.gltf"
done
for _ in $(seq "$REPEATS"); do
  run "cornell path before" "$BEFORE" 5 "$SAMPLES/cornell_room.gltf" --integrator path
  run "cornell path after" "$AFTER" 5 "$SAMPLES/cornell_room.gltf" --integrator path
done
uptime
rm -rf "$OUT"
