#!/usr/bin/python3
"""--guiding auto against unguided path tracing on the CPU, rung by rung (bench/results/guiding-auto.md).

run_time_vs_error.py runs one integrator's whole ladder, then the next: on a machine shared with
other people's builds the load changes between the two ladders (measured here: the unguided Cornell
ladder ran 4x faster at 128 spp than ten minutes earlier), so their seconds do not compare. This
script runs the two integrators alternately at every rung (the order flipping from rung to rung),
each call one bench_time_to_error run of one spp, and reports per rung the time, relMSE and
efficiency ratios and the relMSE at equal time (log-log interpolation, at the longest time both
ladders reached), as run_time_vs_error.py does.

  /usr/bin/python3 bench/run_guiding_auto_pairs.py --build build --out bench/results [--only SCENE,...]
"""
import argparse
import csv
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run_time_vs_error import SCENES, rel_mse_at  # noqa: E402

LADDER_TOP = {"cornell_room": 8192, "courtyard": 4096, "ajar_room": 8192}


def run(build, name, sky, density, reference_spp, spp, integrator):
    tool = os.path.join(build, "bench", "bench_time_to_error")
    command = [tool, os.path.join(build, "samples", name + ".gltf"), "--backends", "cpu", "--integrators", integrator,
               "--name", name, "--texel-density", str(density), "--reference-spp", str(reference_spp),
               "--min-spp", str(spp), "--max-spp", str(spp), "--max-seconds", "1e9"]
    if sky:
        command += ["--sky", sky]
    result = subprocess.run(command, check=True, capture_output=True, text=True)
    for line in result.stderr.splitlines():
        if " auto: " in line:
            print("  " + line, file=sys.stderr, flush=True)
    return list(csv.DictReader(result.stdout.splitlines()))[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="bench/results")
    parser.add_argument("--only", default="cornell_room,courtyard,ajar_room")
    parser.add_argument("--min-spp", type=int, default=16)
    args = parser.parse_args()
    rows = []
    for name, sky, density, reference_spp, _ in SCENES:
        if name not in args.only.split(","):
            continue
        spp, flip = args.min_spp, False
        while spp <= LADDER_TOP.get(name, 4096):
            order = ["guided_auto", "path"] if flip else ["path", "guided_auto"]
            for integrator in order:
                row = run(args.build, name, sky, density, reference_spp, spp, integrator)
                rows.append(row)
                print(f"{name} {row['integrator']} {spp} spp: {float(row['seconds']):.3f} s relMSE {float(row['rel_mse']):.4g}",
                      file=sys.stderr, flush=True)
            spp, flip = spp * 2, not flip
    path = os.path.join(args.out, "guiding_auto_pairs.csv")
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        writer.writeheader()
        writer.writerows(rows)
    print(f"wrote {path}")
    for name in args.only.split(","):
        ladders = {i: [r for r in rows if r["scene"] == name and r["integrator"] == i]
                   for i in ("path_tracing", "path_guided_auto")}
        u, a = ladders["path_tracing"], ladders["path_guided_auto"]
        if not u or not a:
            continue
        print(f"\n{name}: per rung, auto / unguided (efficiency = relMSE x time, unguided / auto: > 1 auto wins)")
        print("| spp | time | relMSE | efficiency |\n|---|---|---|---|")
        efficiencies = []
        for ru, ra in zip(u, a):
            t = float(ra["seconds"]) / float(ru["seconds"])
            e = float(ra["rel_mse"]) / float(ru["rel_mse"])
            efficiencies.append(1 / (t * e))
            print(f"| {ru['spp']} | {t:.2f} | {e:.2f} | {1 / (t * e):.2f} |")
        s = sorted(efficiencies)
        print(f"median efficiency {s[len(s) // 2]:.2f}")
        t = min(float(u[-1]["seconds"]), float(a[-1]["seconds"]))
        eu, ea = rel_mse_at(u, t), rel_mse_at(a, t)
        if eu and ea:
            print(f"relMSE at equal time ({t:.1f} s), unguided / auto: {eu / ea:.3f}")


if __name__ == "__main__":
    main()
