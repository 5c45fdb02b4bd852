#!/usr/bin/env python3
"""Tables and a plot of scripts/validate_fit.sh's batch: one row per case and variant with the
recovered tumour modulus error and the fraction of elements within 1 mm of the true displacement.
Usage: python3 scripts/fit_validation_table.py OUT_DIR SPACING_MM  → OUT_DIR/table.md, validation.png"""
import csv
import json
import os
import re
import sys

TRUE_E = {"dcis": 16400.0, "idc": 20000.0, "fibroadenoma": 6400.0}


def main():
    out, spacing = sys.argv[1], sys.argv[2]
    # From the case folders (a batch stopped midway still gives the finished cases).
    cases_dir = os.path.join(out, "batch", "cases")
    rows = []
    for case in sorted(c for c in os.listdir(cases_dir) if c.isdigit()):
        with open(os.path.join(cases_dir, case, "case.json")) as f:
            info = json.load(f)
        row = {"case": case, "scene": info["values"]["scene"].strip("'\""), "status": info["status"],
               "error": info["error"], "wall_time_s": info["wall_time_s"]}
        if info["status"] == "ok":
            with open(os.path.join(cases_dir, case, "summary.json")) as f:
                row["summary"] = json.load(f)
        rows.append(row)
    lines = ["| case | tumour elements | variant | tumour E fitted (kPa) | true (kPa) | error | adipose error | "
             "fibroglandular error | initial RMS vs obs. (mm) | initial within 1 mm of obs. | within 1 mm of truth | "
             "RMS vs truth (mm) | max vs truth (mm) | iterations | forward solves | wall (s) |",
             "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    points = []
    for r in rows:
        m = re.match(r'cases/(\w+?)_r(\d+)/(\w+)\.toml', r["scene"])
        if not m or r["status"] != "ok":
            lines.append(f"| {r['scene']} | | | {r['status']} {r['error']} |")
            continue
        kind, radius, variant = m.group(1), m.group(2), m.group(3)
        true_e = TRUE_E[kind]
        d = r["summary"]
        mod = d["modulus_pa"]
        fit_e = mod["tumour"]["fitted_E_pa"]
        err = fit_e / true_e - 1
        ad = mod["adipose"]["fitted_E_pa"] / 3250 - 1
        fg = mod["fibroglandular"]["fitted_E_pa"] / 6000 - 1
        within = d["truth"]["within_1mm"]
        wall = r["wall_time_s"]
        lines.append(f"| {kind} r = {radius} mm | {mod['tumour']['elements']} | {variant} | {fit_e / 1e3:.2f} | "
                     f"{true_e / 1e3:.1f} | {100 * err:+.1f}% | {100 * ad:+.2f}% | {100 * fg:+.2f}% | "
                     f"{d['initial']['rms_mm']:.3f} | {100 * d['initial']['within_1mm']:.2f}% | "
                     f"{100 * within:.2f}% | {d['truth']['rms_mm']:.4f} | {d['truth']['max_mm']:.3f} | "
                     f"{d['iterations']} | {d['forward_solves']} | "
                     f"{wall:.1f} |")
        points.append((f"{kind}\nr{radius}", variant, err))
    text = f"Lattice spacing {spacing} mm.\n\n" + "\n".join(lines) + "\n"
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write(text)
    print(text)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return 0
    labels = sorted({p[0] for p in points}, key=lambda s: [p[0] for p in points].index(s))
    variants = ["linear", "noisy", "neo_hookean", "bisection"]
    fig, ax = plt.subplots(figsize=(9, 3.6))
    width = 0.2
    for i, v in enumerate(variants):
        ys = [next((100 * p[2] for p in points if p[0] == lab and p[1] == v), float("nan")) for lab in labels]
        ax.bar([k + (i - 1.5) * width for k in range(len(labels))], ys, width, label=v)
    ax.axhspan(-10, 10, color="green", alpha=0.1, label="goal ±10%")
    ax.axhline(0, color="k", lw=0.6)
    ax.set_xticks(range(len(labels)))
    ax.set_xticklabels(labels, fontsize=8)
    ax.set_ylabel("tumour modulus error (%)")
    ax.set_title(f"Recovered tumour modulus, {spacing} mm lattice")
    ax.legend(fontsize=7, ncol=5)
    ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "validation.png"), dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
