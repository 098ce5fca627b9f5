# Sourced by bench/light_paths_gpu_run.sh and bench/light_paths_lavapipe_run.sh: the modes they
# compare (exitance-relight with and without --light-paths on, and with EMITTER=1 emitter guiding
# alone and beside them), run and printed the same way on both machines.
# The caller sets R (exitance-relight), B (the bundle), W (a work folder) and PREFIX (the runs' name
# prefix, may be empty). Each run's line goes to stdout; its bundle joins $list for bench_bundle_rel_mse.
common="--ignore-baked --no-light-layers --json"

# Every mode's kernels built once before any timed run (the driver's or lavapipe's pipeline caches;
# the first emitter-guided run built them inside its budget otherwise: 1 sample at 0.25 s on an H100),
# then the two 4096-spp references without subpaths (seeds 101, 202).
light_paths_warm_and_references() {
  $R $B -o $W/warm.bake --spp 4 --seed 1 $common > /dev/null
  $R $B -o $W/warm.bake --spp 4 --seed 1 --light-paths on $common > /dev/null
  if [ "${EMITTER:-0}" = 1 ]; then
    $R $B -o $W/warm.bake --spp 4 --seed 1 --emitter-guiding on --light-paths on $common > /dev/null
  fi
  for s in 101 202; do $R $B -o $W/ref_$s.bake --spp 4096 --seed $s $common > /dev/null; done
  list=""
}

light_paths_run() {  # NAME ARGS...
  local name=$PREFIX$1; shift
  $R $B -o $W/$name.bake --seed 3 $common "$@" > $W/$name.json
  python3 -c "
import json; r=json.load(open('$W/$name.json'))
print('$name', 'lighting_s %.3f'%r['lighting_seconds'], 'spp', r['samples_per_texel'], 'rays %.3g'%r['rays'], 'rays_per_s %.3g'%r['rays_per_second'], 'light_paths', r.get('light_paths'))"
  list="$list $W/$name.bake"
}

# At each of the times (--time: both modes the progressive refresh; the emitter-guided ones whole runs).
light_paths_at_times() {  # SECONDS...
  local t
  for t in "$@"; do
    light_paths_run off_t$t --time $t
    light_paths_run on_t$t --time $t --light-paths on
    if [ "${EMITTER:-0}" = 1 ]; then
      light_paths_run eg_t$t --time $t --emitter-guiding on
      light_paths_run egon_t$t --time $t --emitter-guiding on --light-paths on
    fi
  done
}

light_paths_in_frames() {  # FRAMES BUDGET_MS
  light_paths_run off_f$1 --frames $1 --budget-ms $2 --spp 0 --no-frame-errors
  light_paths_run on_f$1 --frames $1 --budget-ms $2 --spp 0 --no-frame-errors --light-paths on
}
