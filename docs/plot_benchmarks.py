#!/usr/bin/python3
"""Draws the scaling plot of docs/benchmarks.md from the CSV that morph-bench writes.

    build-bench/bench/morph-bench --scaling --csv bench-results
    /usr/bin/python3 docs/plot_benchmarks.py bench-results/scaling.csv docs/img/bench_scaling.png

Log-log: libmorph's time (1 thread, median) against input facets (|F_A| + |F_B|), one
line per series, each with its least-squares slope over the cases of >= 1000 input
facets (below that, fixed costs dominate), and a dashed slope-1 reference.
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FIT_FROM = 1000  # input facets; the same cut as the slope printed by morph-bench


def slope(xs, ys):
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    n = len(lx)
    mx, my = sum(lx) / n, sum(ly) / n
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def main(csv_path, png_path):
    series = {}
    with open(csv_path, newline="") as f:
        for row in csv.DictReader(f):
            series.setdefault(row["series"], []).append(
                (float(row["input facets"]), float(row["1 thread (ms)"]), float(row["output facets"])))

    fig, ax = plt.subplots(figsize=(7, 5))
    for name, points in series.items():
        points.sort()
        xs = [p[0] for p in points]
        ys = [p[1] for p in points]
        fit = [(x, y) for x, y in zip(xs, ys) if x >= FIT_FROM]
        label = name
        if len(fit) >= 2:
            label += f"  (slope {slope([p[0] for p in fit], [p[1] for p in fit]):.2f})"
        ax.loglog(xs, ys, "o-", label=label)
    all_x = [p[0] for points in series.values() for p in points]
    all_y = [p[1] for points in series.values() for p in points]
    x0, x1 = min(all_x), max(all_x)
    y_ref = max(all_y) / x1  # slope-1 line through the top right corner
    ax.loglog([x0, x1], [y_ref * x0, y_ref * x1], "k--", linewidth=1, label="slope 1")
    ax.set_xlabel("input facets |F_A| + |F_B|")
    ax.set_ylabel("A (+) B, libmorph, 1 thread (ms, median)")
    ax.set_title("libmorph Minkowski sum: time against input size")
    ax.grid(True, which="both", linewidth=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)
    print(f"wrote {png_path}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: plot_benchmarks.py SCALING_CSV OUTPUT_PNG")
    main(sys.argv[1], sys.argv[2])
