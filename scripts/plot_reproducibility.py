#!/usr/bin/env python3
"""Tumour centroids of a reproducibility study (OUT/reproducibility.csv, docs/POSITIONING.md):
one point per perturbed posture, with and without the device, in the plane across the breast's
axis and along it, with each configuration's mean and RMS spread.
  /usr/bin/python3 scripts/plot_reproducibility.py OUT_DIR picture.png
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    rows = list(csv.DictReader(open(sys.argv[1] + "/reproducibility.csv")))
    if not rows:
        sys.exit("reproducibility.csv has no runs")
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.5))
    for device, colour, label in (("1", "tab:red", "with the device"), ("0", "tab:grey", "without a device")):
        pts = [(float(r["tumour_x_mm"]), float(r["tumour_y_mm"]), float(r["tumour_z_mm"])) for r in rows if r["device"] == device]
        if not pts:
            continue
        mean = [sum(p[c] for p in pts) / len(pts) for c in range(3)]
        rms = math.sqrt(sum(sum((p[c] - mean[c]) ** 2 for c in range(3)) for p in pts) / len(pts))
        for ax, (a, b) in zip(axes, ((0, 2), (0, 1))):
            ax.scatter([p[a] for p in pts], [p[b] for p in pts], color=colour, label=f"{label}: RMS spread {rms:.2f} mm")
            ax.scatter([mean[a]], [mean[b]], color=colour, marker="+", s=200)
            ax.add_patch(plt.Circle((mean[a], mean[b]), rms, color=colour, fill=False, linestyle="--"))
    for ax, (xl, yl) in zip(axes, (("x (L, mm)", "z (S, mm)"), ("x (L, mm)", "y (P, mm)"))):
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    axes[0].set_title("tumour centroid across the breast's axis")
    axes[1].set_title("and along it (y)")
    axes[0].legend(loc="best", fontsize=8)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=110)


if __name__ == "__main__":
    main()
