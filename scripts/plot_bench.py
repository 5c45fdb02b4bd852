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
    # One series per model family, law, integrator and precision: the cubes, and the breast phantom
    # at its resampled sizes (dashed; two thirds of its elements are the held chest wall). Rows with
    # the volume constraint are left out.
    series = {}
    for r in rows:
        if r["model"] == "block":
            family = ""
        elif r["model"] in ("breast", "breast_large", "breast_resampled"):
            family = "phantom: "
        else:
            continue
        law = "" if r["law"] == "linear" else f'{r["law"]}, '
        key = f'{family}{law}{r["integrator"]}, {r["precision"]}'
        series.setdefault(key, []).append((int(r["elements"]), float(r["steps_per_s"]), float(r["ns_per_element_step"])))
        # the gather floor measured beside the row (the same kernels without their arithmetic;
        # engine/bench/gather_floor.hpp), where the row's step is the one it mirrors
        if r.get("gather_floor_steps_per_s"):
            floor = float(r["gather_floor_steps_per_s"])
            series.setdefault(f"gather floor of {key}", []).append((int(r["elements"]), floor, 1e9 / (floor * int(r["elements"]))))
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    for key, pts in sorted(series.items()):
        pts.sort()
        n = [p[0] for p in pts]
        style = "s--" if key.startswith("phantom") else "k^:" if key.startswith("gather floor") else "o-"
        a.loglog(n, [p[1] for p in pts], style, label=key)
        b.semilogx(n, [p[2] for p in pts], style, label=key)
    a.set_xlabel("elements")
    a.set_ylabel("steps / s")
    a.set_title(f"{title}: linear springs unless named")
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
