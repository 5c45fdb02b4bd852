#!/usr/bin/python3
"""PNG plots of a `voxbreast sweep`: every metric of metrics.csv against every varied parameter.

    /usr/bin/python3 scripts/plot_sweep.py out/sweep [--overview METRIC,METRIC,...]

Writes DIR/plots/<metric>.png (one panel per varied parameter; in each panel one line per
combination of the other parameters) for every numeric metric that varies over the cases, and
DIR/plots/overview.png: the headline metrics (tracked-point displacements, maximum displacement,
contact forces and pressures, or those named by --overview), one row each. Failed and pending
cases are left out. `voxbreast sweep` runs this at the end; run it by hand to redraw.
"""
import argparse
import csv
import json
import math
import os
import re
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("plot_sweep.py: matplotlib is missing (Debian: apt-get install python3-matplotlib)", file=sys.stderr)
    sys.exit(77)

HEADLINE = re.compile(r"(displacement_norm_m|max_displacement_m|contact.*_n$|pressure|separation)")
MAX_LEGEND = 8


def number(text):
    """float of a CSV cell, or None (empty, words, arrays)."""
    if text in ("true", "false"):
        return float(text == "true")
    try:
        x = float(text)
    except ValueError:
        return None
    return x if math.isfinite(x) else None


def read(folder):
    sweep = json.load(open(os.path.join(folder, "sweep.json")))
    keys = [p["key"] for p in sweep["parameters"]]
    with open(os.path.join(folder, "metrics.csv"), newline="") as f:
        reader = csv.reader(f)
        header = next(reader)
        rows = [dict(zip(header, r)) for r in reader]
    first_metric = header.index("error") + 1
    ok = [r for r in rows if r["status"] == "ok"]
    metrics = []
    for m in header[first_metric:]:
        values = [number(r[m]) for r in ok]
        if all(v is not None for v in values) and len(set(values)) > 1:
            metrics.append(m)
    return keys, ok, metrics


def axis_values(rows, key):
    """x positions for a parameter: its numbers, or category positions for words and arrays."""
    raw = [r[key] for r in rows]
    if all(number(v) is not None for v in raw):
        return [number(v) for v in raw], None
    categories = list(dict.fromkeys(raw))
    return [categories.index(v) for v in raw], categories


def panel(ax, rows, keys, key, metric, show_legend):
    x, categories = axis_values(rows, key)
    others = [k for k in keys if k != key]
    groups = {}
    for xi, r in zip(x, rows):
        label = ", ".join(f"{k}={r[k]}" for k in others)
        groups.setdefault(label, []).append((xi, number(r[metric])))
    style = "o-" if categories is None else "o:"  # dotted: categories have no order in between
    for label, points in groups.items():
        points.sort()
        ax.plot([p[0] for p in points], [p[1] for p in points], style, ms=4, label=label or None)
    if categories is not None:
        ax.set_xticks(range(len(categories)))
        ax.set_xticklabels(categories)
        ax.set_xlim(-0.5, len(categories) - 0.5)
    elif min(x) > 0 and max(x) / min(x) >= 100:
        ax.set_xscale("log")
    ax.set_xlabel(key)
    ax.grid(True, alpha=0.3)
    if show_legend and others and 1 < len(groups) <= MAX_LEGEND:
        ax.legend(fontsize=7)


def file_name(metric):
    return re.sub(r"[^A-Za-z0-9_.-]", "_", metric) + ".png"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder")
    parser.add_argument("--overview", help="comma list of metrics for overview.png")
    args = parser.parse_args()
    keys, rows, metrics = read(args.folder)
    out = os.path.join(args.folder, "plots")
    os.makedirs(out, exist_ok=True)
    if not rows or not keys or not metrics:
        print(f"plot_sweep.py: nothing to plot in {args.folder} (no finished case, parameter or varying metric)")
        return 0
    for metric in metrics:
        fig, axes = plt.subplots(1, len(keys), figsize=(4.2 * len(keys), 3.4), squeeze=False)
        for ax, key in zip(axes[0], keys):
            panel(ax, rows, keys, key, metric, show_legend=True)
        axes[0][0].set_ylabel(metric)
        fig.suptitle(metric, fontsize=10)
        fig.tight_layout()
        fig.savefig(os.path.join(out, file_name(metric)), dpi=90)
        plt.close(fig)

    overview = args.overview.split(",") if args.overview else [m for m in metrics if HEADLINE.search(m)][:6]
    overview = [m for m in overview if m in metrics] or metrics[:4]
    fig, axes = plt.subplots(len(overview), len(keys), figsize=(4.2 * len(keys), 2.8 * len(overview)), squeeze=False)
    for i, metric in enumerate(overview):
        for j, key in enumerate(keys):
            panel(axes[i][j], rows, keys, key, metric, show_legend=(i == 0))
        axes[i][0].set_ylabel(metric, fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "overview.png"), dpi=90)
    plt.close(fig)
    print(f"wrote {len(metrics) + 1} plots in {out}/ (overview.png and one per metric)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
