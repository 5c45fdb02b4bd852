#!/usr/bin/python3
"""Plots a `voxbreast bench` study: error against wall time to equilibrium with the Pareto front
(one panel per scene), and steps/s against element count.

    /usr/bin/python3 scripts/plot_bench_study.py out/bench docs/img/bench_study_pocl-2cores_DATE_COMMIT "PoCL, 2 cores"

Reads OUT/bench.csv (and OUT/throughput.csv when present); writes PREFIX_pareto.png and
PREFIX_scaling.png.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

LAW_COLOURS = {"linear": "tab:blue", "biphasic": "tab:orange", "neo-hookean": "tab:green", "ogden": "tab:red"}
PART_MARKERS = {"base": "*", "grid": "o", "resolution": "s", "time_step": "^", "volume": "D", "tolerance": "v"}


def short(r):
    """The knobs that differ from the base case, for labelling Pareto points."""
    parts = [r["law"], "euler" if r["integrator"] == "symplectic_euler" else r["integrator"], r["precision"]]
    if r["downsample"] != "1":
        parts.append(f'd{r["downsample"]}')
    if float(r["dt_factor"]) != 1:
        parts.append(f'dt×{float(r["dt_factor"]):g}')
    if r["volume"] == "on":
        parts.append("vol")
    if r["part"] == "tolerance":
        parts.append(f'tol {float(r["tolerance"]):g}')
    return " ".join(parts)


def pareto(points):
    """Points not beaten in both wall time and error by another, sorted by wall time."""
    front, best = [], float("inf")
    for p in sorted(points, key=lambda p: (p[0], p[1])):
        if p[1] < best:
            front.append(p)
            best = p[1]
    return front


def main(out_dir, prefix, title):
    rows = list(csv.DictReader(open(os.path.join(out_dir, "bench.csv"))))
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    fig, axes = plt.subplots(1, len(scenes), figsize=(6.5 * len(scenes), 5.2), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        runs = [r for r in rows if r["scene"] == scene and r["part"] != "reference"]
        shown = [r for r in runs if r["status"] in ("ok", "not_converged") and r["error_rms_mm"] not in ("", "0")]
        for r in shown:
            ax.loglog(float(r["wall_s"]), float(r["error_rms_mm"]), PART_MARKERS.get(r["part"], "o"),
                      color=LAW_COLOURS.get(r["law"], "k"), alpha=0.8,
                      markerfacecolor="none" if r["precision"] == "double" else LAW_COLOURS.get(r["law"], "k"),
                      markersize=11 if r["part"] == "base" else 7)
        front = pareto([(float(r["wall_s"]), float(r["error_rms_mm"]), r) for r in shown])
        ax.step([p[0] for p in front], [p[1] for p in front], where="post", color="k", lw=1, alpha=0.6)
        for x, y, r in front:
            ax.annotate(short(r), (x, y), fontsize=7, xytext=(4, 3), textcoords="offset points")
        unstable = [r for r in runs if r["status"] == "unstable"]
        note = f"\n{len(unstable)} unstable run(s) not shown" if unstable else ""
        ax.set_title(f"{scene}: {int(float(shown[0]['elements'])) if shown else 0:,} elements at full resolution{note}",
                     fontsize=10)
        ax.set_xlabel("wall time to equilibrium (s)")
        ax.set_ylabel("RMS displacement error vs reference (mm)")
        ax.grid(True, which="both", alpha=0.3)
    handles = [plt.Line2D([], [], color=c, marker="o", ls="", label=l) for l, c in LAW_COLOURS.items()]
    handles += [plt.Line2D([], [], color="gray", marker=m, ls="", label=p.replace("_", " ")) for p, m in PART_MARKERS.items()]
    handles += [plt.Line2D([], [], color="gray", marker="o", markerfacecolor="none", ls="", label="double (hollow)")]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    fig.suptitle(f"{title}: speed against accuracy (black: Pareto front)")
    fig.tight_layout(rect=(0, 0.06, 1, 0.97))
    fig.savefig(prefix + "_pareto.png", dpi=100)

    fig, ax = plt.subplots(figsize=(7.5, 5))
    for r in rows:
        if r["status"] not in ("ok", "not_converged") or r["steps_per_s"] == "":
            continue
        ax.loglog(float(r["elements"]), float(r["steps_per_s"]), "o" if r["integrator"] == "heun" else "^",
                  color=LAW_COLOURS.get(r["law"], "k"), alpha=0.6,
                  markerfacecolor="none" if r["precision"] == "double" else LAW_COLOURS.get(r["law"], "k"))
    handles = [plt.Line2D([], [], color=c, marker="o", ls="", label=l) for l, c in LAW_COLOURS.items()]
    handles += [plt.Line2D([], [], color="gray", marker="^", ls="", label="symplectic Euler"),
                plt.Line2D([], [], color="gray", marker="o", markerfacecolor="none", ls="", label="double (hollow)")]
    throughput = os.path.join(out_dir, "throughput.csv")
    if os.path.exists(throughput):
        series = {}
        for r in csv.DictReader(open(throughput)):
            series.setdefault((r["law"], r["integrator"], r["precision"]), []).append(
                (int(r["elements"]), float(r["steps_per_s"])))
        for (law, integrator, precision), pts in sorted(series.items()):
            pts.sort()
            style = "--" if integrator != "heun" else ":" if precision == "double" else "-"
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, lw=1, color=LAW_COLOURS.get(law, "k"))
        handles += [plt.Line2D([], [], color="gray", ls="-", label="cubes (--sizes): Heun float"),
                    plt.Line2D([], [], color="gray", ls="--", label="cubes: Euler float"),
                    plt.Line2D([], [], color="gray", ls=":", label="cubes: Heun double")]
    ax.legend(handles=handles, fontsize=8, loc="lower left")
    ax.set_xlabel("elements")
    ax.set_ylabel("steps / s (checks included)")
    ax.set_title(f"{title}: steps/s against element count, every bench run")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(prefix + "_scaling.png", dpi=100)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else "")
