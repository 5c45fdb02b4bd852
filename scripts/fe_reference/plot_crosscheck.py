#!/usr/bin/env python3
"""Plots the FE cross-check: |error| of VoxBreast against the FE reference per spacing, one line
per case and law, for one or more crosscheck CSVs (e.g. two builds side by side).

  python3 scripts/fe_reference/plot_crosscheck.py --out docs/img/fe_crosscheck.png \
      LABEL=docs/results/fe_crosscheck_....csv [LABEL2=other.csv]
"""
import argparse
import csv

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--precision", default="double")
    ap.add_argument("inputs", nargs="+", help="LABEL=CSV")
    args = ap.parse_args()

    panels = len(args.inputs)
    fig, axes = plt.subplots(1, panels, figsize=(6.2 * panels, 4.6), squeeze=False, sharey=True)
    for ax, spec in zip(axes[0], args.inputs):
        label, path = spec.split("=", 1)
        series = {}
        with open(path) as f:
            for row in csv.DictReader(f):
                if row["precision"] != args.precision or not row["error_pct"]:
                    continue
                series.setdefault(f"{row['case']} ({row['law']})", []).append(
                    (float(row["h_mm"]), abs(float(row["error_pct"]))))
        for name, pts in sorted(series.items()):
            pts.sort()
            ax.loglog([p[0] for p in pts], [max(p[1], 1e-2) for p in pts], "o-", label=name)
        for goal_h, goal in ((2, 2.0), (4, 5.0)):
            ax.plot([goal_h], [goal], "k*", markersize=12)
        ax.axhline(2.0, color="0.6", lw=0.8, ls=":")
        ax.axhline(5.0, color="0.6", lw=0.8, ls="--")
        ax.set_xlabel("spacing h (mm)")
        ax.set_title(f"{label} ({args.precision})")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xticks([1, 2, 4])
        ax.set_xticklabels(["1", "2", "4"])
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    axes[0][0].set_ylabel("|VoxBreast − FE| / FE (%), floored at 0.01%\n★: goals, 2% at 2 mm and 5% at 4 mm")
    axes[0][-1].legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"plot_crosscheck: wrote {args.out}")


if __name__ == "__main__":
    main()
