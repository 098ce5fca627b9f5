#!/usr/bin/python3
"""Time against error over the bench scene suite (DESIGN §7).

Runs bench_time_to_error for every backend x integrator x scene, writes one CSV, draws a
log-log plot of relMSE against seconds per scene (matplotlib), and a Markdown table of the
time to reach the target relMSE and of relMSE at equal time, as ratios to the CPU reference
measured in the same run. References are cached by content hash in ~/.cache/exitance.

  /usr/bin/python3 bench/run_time_vs_error.py --build build --out bench/results [--quick]
      [--integrators path,bounces] [--report NAME] [--only SCENE,SCENE] [--ladder-scale K]

--report names the CSV, plot and table (default time_vs_error); the per-bounce mode's figures
(bench/results/per-bounce.md) come from --backends cpu --integrators path,bounces --report per-bounce;
grid guiding's (bench/results/guiding.md) from --backends cpu --integrators path,guided --report guiding_time_vs_error;
SVO guiding's (bench/results/guiding-svo.md) from --integrators path,guided,svo (--tool-args passes
e.g. --tool-args="--svo-depth 7 --svo-c-ray 256" on to bench_time_to_error; write it with =).
--guiding auto's (bench/results/guiding-auto.md) from --backends cpu --integrators path,guided_auto --report guiding_auto_time_vs_error.
Emitter guiding's (bench/results/emitter-guiding.md) from --backends cpu --integrators path,nee --report emitter_guiding_time_vs_error.
--ladder-scale multiplies every scene's largest spp (longer ladders, e.g. to reach 20 s).
The table's last column: relMSE of the CPU path tracer divided by this row's, both interpolated
(log-log) at the same time, the longest both reached: > 1 = better than the CPU path tracer.

(Debian's python3 has python3-matplotlib; a pyenv python3 on PATH may not.)
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import time

# name, sky, texel density, reference spp, max spp of the ladder
SCENES = [
    ("cornell_room", "", 4, 16384, 2048),
    ("courtyard", "0.5,0.6,0.8", 2, 4096, 1024),
    ("ajar_room", "", 4, 32768, 4096),
    ("building", "", 0.5, 512, 256),
    ("thin_walls", "", 8, 8192, 1024),
]


def run_scene(build, backends, integrators, name, sky, density, reference_spp, max_spp, max_seconds, target, tool_args=""):
    tool = os.path.join(build, "bench", "bench_time_to_error")
    scene = os.path.join(build, "samples", name + ".gltf")
    command = [tool, scene, "--backends", backends, "--integrators", integrators, "--name", name, "--texel-density", str(density), "--reference-spp", str(reference_spp),
               "--max-spp", str(max_spp), "--max-seconds", str(max_seconds), "--target", str(target)]
    if sky:
        command += ["--sky", sky]
    command += tool_args.split()
    print("+", " ".join(command), file=sys.stderr, flush=True)
    result = subprocess.run(command, check=True, capture_output=True, text=True)
    sys.stderr.write(result.stderr)
    return list(csv.DictReader(result.stdout.splitlines())), command


def rel_mse_at(rows, seconds):
    """relMSE at `seconds`, log-log interpolated between the ladder's runs; None outside them."""
    points = [(float(r["seconds"]), float(r["rel_mse"])) for r in rows]
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if t0 <= seconds <= t1 and t0 > 0 and t1 > t0:
            f = (math.log(seconds) - math.log(t0)) / (math.log(t1) - math.log(t0))
            return math.exp(math.log(e0) + f * (math.log(e1) - math.log(e0)))
    if points and abs(points[-1][0] - seconds) < 1e-9:
        return points[-1][1]
    return None


def time_to_target(rows, target):
    """Seconds at which relMSE crosses the target, log-log interpolated; None if never."""
    previous = None
    for row in rows:
        t, e = float(row["seconds"]), float(row["rel_mse"])
        if e <= target:
            if previous is None:
                return t
            t0, e0 = previous
            f = (math.log(target) - math.log(e0)) / (math.log(e) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t) - math.log(t0)))
        previous = (t, e)
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="bench/results")
    parser.add_argument("--target", type=float, default=0.01)
    parser.add_argument("--max-seconds", type=float, default=60)
    parser.add_argument("--only", default="")
    parser.add_argument("--backends", default="cpu,vulkan")
    parser.add_argument("--integrators", default="path")
    parser.add_argument("--report", default="time_vs_error")
    parser.add_argument("--quick", action="store_true", help="4x fewer reference and ladder samples")
    parser.add_argument("--ladder-scale", type=int, default=1, help="multiply every scene's largest spp")
    parser.add_argument("--tool-args", default="", help="extra arguments for bench_time_to_error")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    all_rows, commands = [], []
    for name, sky, density, reference_spp, max_spp in SCENES:
        if args.only and name not in args.only.split(","):
            continue
        max_spp *= args.ladder_scale
        if args.quick:
            reference_spp, max_spp = max(64, reference_spp // 4), max(16, max_spp // 4)
        rows, command = run_scene(args.build, args.backends, args.integrators, name, sky, density, reference_spp, max_spp, args.max_seconds, args.target, args.tool_args)
        all_rows += rows
        commands.append(" ".join(command))

    stamp = time.strftime("%Y-%m-%d")
    csv_path = os.path.join(args.out, args.report + ".csv")
    with open(csv_path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(all_rows[0].keys()))
        writer.writeheader()
        writer.writerows(all_rows)

    groups = {}
    for row in all_rows:
        groups.setdefault((row["scene"], row["backend"], row["integrator"]), []).append(row)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scenes = sorted({key[0] for key in groups})
    fig, axes = plt.subplots(1, len(scenes), figsize=(4.2 * len(scenes), 3.8), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        for (s, backend, integrator), rows in sorted(groups.items()):
            if s != scene:
                continue
            ax.loglog([float(r["seconds"]) for r in rows], [float(r["rel_mse"]) for r in rows], "o-",
                      label=f"{backend} {integrator}")
        ax.axhline(args.target, color="grey", linestyle=":", linewidth=1)
        ax.set_title(scene)
        ax.set_xlabel("lighting seconds (2 cores)")
        ax.set_ylabel("relMSE")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    png_path = os.path.join(args.out, args.report + ".png")
    fig.savefig(png_path, dpi=110)

    lines = [f"# Time against error ({stamp})", "",
             "Produced by:", "", "```", "/usr/bin/python3 bench/run_time_vs_error.py " + " ".join(sys.argv[1:]), "```", "",
             "which ran:", "", "```"] + commands + ["```", "",
             f"relMSE = mean over texels and channels of (x - r)^2 / (r^2 + 1e-3), minus the reference's own expected "
             f"relMSE (column reference_rel_mse of {os.path.basename(csv_path)}). Machine: 2 shared cores; absolute "
             "seconds are noisy, ratios inside one run are what count.", "",
             f"| scene | backend | integrator | live texels | time to relMSE {args.target:g} (s) | relMSE at the largest run | "
             "rays/s | ratio of time to the CPU reference | bounces, bias relMSE (per-bounce) | "
             "relMSE gain over the CPU path tracer at equal time |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for (scene, backend, integrator), rows in sorted(groups.items()):
        t = time_to_target(rows, args.target)
        base = time_to_target(groups.get((scene, "cpu", "path_tracing"), []), args.target)
        ratio = f"{t / base:.2f}" if t and base else "-"
        last = rows[-1]
        lines.append(f"| {scene} | {backend} | {integrator} | {last['live_texels']} | "
                     f"{t:.3g}" if t else f"| {scene} | {backend} | {integrator} | {last['live_texels']} | not reached")
        lines[-1] += (f" | {float(last['rel_mse']):.3g} at {float(last['seconds']):.3g} s ({last['spp']} spp) | "
                      f"{float(last['rays_per_second']) / 1e6:.2f} M | {ratio} |")
        if integrator == "per_bounce":
            lines[-1] += f" {last['bounces']}, {float(last['bias_rel_mse']):.2g} |"
        else:
            lines[-1] += " - |"
        base_rows = groups.get((scene, "cpu", "path_tracing"), [])
        gain = "-"
        if base_rows and base_rows is not rows:
            t_equal = min(float(rows[-1]["seconds"]), float(base_rows[-1]["seconds"]))
            mine, theirs = rel_mse_at(rows, t_equal), rel_mse_at(base_rows, t_equal)
            if mine and theirs:
                gain = f"{theirs / mine:.2f} at {t_equal:.3g} s"
        lines[-1] += f" {gain} |"
    lines += ["", f"![time against error]({os.path.basename(png_path)})", ""]
    with open(os.path.join(args.out, args.report + ".md"), "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
