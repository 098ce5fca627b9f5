#!/usr/bin/python3
"""Images of learned grid guiding tables or SVO guiding fields (issue 11): the CSV of
bench_time_to_error --guiding-fields (grid runs: one row per grid cell x class; svo runs: one row per
(bin, class) record with its bin's octree level and capture origin).

  /usr/bin/python3 bench/plot_guiding_fields.py FIELDS.csv OUT.png [--title NAME] [--count 8]

Each panel is one record (grid cell x normal class): its 16 x 16 bins on the concentric square of
the class hemisphere (centre = along the class normal, edges = grazing), incident radiance
(luminance) on a log scale. Shown: the records whose tables are most peaked (max / mean), where
guiding departs most from cosine sampling.
"""
import argparse
import csv
import math

CLASSES = ["+x", "-x", "+y", "-y", "+z", "-z"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("fields")
    parser.add_argument("out")
    parser.add_argument("--title", default="")
    parser.add_argument("--count", type=int, default=8)
    args = parser.parse_args()
    rows = list(csv.DictReader(open(args.fields)))
    bins = [k for k in rows[0] if k.startswith("bin")]
    side = int(round(math.sqrt(len(bins))))
    records = []
    for r in rows:
        values = [float(r[b]) for b in bins]
        mean = sum(values) / len(values)
        if mean <= 0:
            continue
        records.append((max(values) / mean, r, values))
    records.sort(key=lambda t: -t[0])
    chosen = records[: args.count]

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm
    cols = min(4, len(chosen))
    rows_n = (len(chosen) + cols - 1) // cols
    fig, axes = plt.subplots(rows_n, cols, figsize=(3.1 * cols, 3.0 * rows_n), squeeze=False)
    for ax in axes.flat:
        ax.axis("off")
    for ax, (peak, r, values) in zip(axes.flat, chosen):
        grid = [[max(values[j * side + i], 1e-6) for i in range(side)] for j in range(side)]
        image = ax.imshow(grid, origin="lower", norm=LogNorm(vmin=max(min(min(g) for g in grid), max(values) * 1e-4),
                                                             vmax=max(values)), cmap="magma")
        where = (f"cell ({r['cell_x']},{r['cell_y']},{r['cell_z']})" if "cell_x" in r else
                 f"level {r['level']} at ({float(r['x']):.2f},{float(r['y']):.2f},{float(r['z']):.2f})")
        ax.set_title(f"{where} {CLASSES[int(r['normal_class'])]}\nmax/mean {peak:.1f}", fontsize=8)
        ax.axis("on")
        ax.set_xticks([])
        ax.set_yticks([])
        fig.colorbar(image, ax=ax, fraction=0.046, pad=0.04)
    size = f"cell {float(rows[0]['cell_size']):.3g} units" if "cell_size" in rows[0] else "SVO fields"
    fig.suptitle(args.title + f" ({size}, {len(rows)} records)", fontsize=9)
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)


if __name__ == "__main__":
    main()
