#!/usr/bin/python3
"""Plots `voxbreast bench` results: steps/s and ns per element-step against element count.

    /usr/bin/python3 scripts/plot_bench.py out/bench/bench.csv docs/img/bench_scaling_h200.png "NVIDIA H200"
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main(csv_path, png_path, title):
    rows = list(csv.DictReader(open(csv_path)))
    series = {}
    for r in rows:
        key = f'{r["integrator"]}, {r["precision"]}'
        series.setdefault(key, []).append((int(r["elements"]), float(r["steps_per_s"]), float(r["ns_per_element_step"])))
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    for key, pts in sorted(series.items()):
        pts.sort()
        n = [p[0] for p in pts]
        a.loglog(n, [p[1] for p in pts], "o-", label=key)
        b.semilogx(n, [p[2] for p in pts], "o-", label=key)
    a.set_xlabel("elements")
    a.set_ylabel("steps / s")
    a.set_title(f"{title}: linear springs, block models")
    a.grid(True, which="both", alpha=0.3)
    a.legend()
    b.set_xlabel("elements")
    b.set_ylabel("ns per element-step")
    b.set_title("cost per element (flat = linear scaling)")
    b.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else "")
