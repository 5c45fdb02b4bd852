#!/usr/bin/python3
"""Plots the large-deformation self-weight study (a 3 cm neo-Hookean cube hanging from its held top
face) from the CSV that the long test writes.

    VOXBREAST_VALIDATION_OUT=/tmp build/tests/test_physics --gtest_filter='SelfWeightConvergenceStudy.*'
    /usr/bin/python3 scripts/plot_self_weight.py /tmp/self_weight_convergence.csv docs/img/self_weight_convergence.png

The docs figure adds the 0.375 mm level (VOXBREAST_SELF_WEIGHT_FINEST=81, run on a GPU; levels
to 0.75 mm take about 1 h on 2 CPU cores). The limit of each sequence is Richardson's
extrapolation with the order observed on its three finest levels, as in the test.
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

# case name in the CSV → (label, style, colour)
FULL_LOAD = {
    "nh_nu0.45_g1": ("neo-Hookean ν 0.45, hull masses (the model)", "o-", "C0"),
    "nh_nu0.45_g1_voxelmass": ("neo-Hookean ν 0.45, voxel masses (diagnostic)", "s--", "C1"),
    "linear_nu0.25_g1": ("linear springs (ν 1/4)", "^-", "C2"),
}
SMALL_LOAD = {
    "nh_nu0.45_g0.03": ("neo-Hookean ν 0.45", "o-", "C3"),
    "nh_nu0.25_g0.03": ("neo-Hookean ν 0.25", "d-", "C4"),
    "linear_nu0.25_g0.03": ("linear springs (ν 1/4)", "^-", "C5"),
    "nh_nu0.45_g0.03_voxelmass": ("neo-Hookean ν 0.45, voxel masses", "s--", "C1"),
}


def read(csv_path):
    """case → list of (h in mm, q in mm, g scale, peak axis strain), coarse to fine"""
    runs = {}
    with open(csv_path, newline="") as f:
        for row in csv.DictReader(f):
            runs.setdefault(row["case"], []).append((1e3 * float(row["h_m"]), 1e3 * float(row["q_m"]),
                                                     float(row["g_scale"]), float(row["peak_axis_strain"])))
    for r in runs.values():
        r.sort(key=lambda x: -x[0])
    return runs


def order_and_limit(q):
    """observed order on the three finest levels and the extrapolated limit (None if not monotone)"""
    d1, d2 = q[-3] - q[-2], q[-2] - q[-1]
    if d1 * d2 <= 0:
        return None, q[-1]
    p = math.log2(abs(d1) / abs(d2))
    if not 0.5 < p < 3:
        return None, q[-1]
    return p, q[-1] + (q[-1] - q[-2]) / (2**p - 1)


def fitted_slope(h, err):
    """least-squares slope of log err against log h"""
    x = [math.log(v) for v in h]
    y = [math.log(v) for v in err]
    mx, my = sum(x) / len(x), sum(y) / len(y)
    return sum((a - mx) * (b - my) for a, b in zip(x, y)) / sum((a - mx) ** 2 for a in x)


def main(csv_path, png_path):
    runs = read(csv_path)
    fig, ((a, b), (c, d)) = plt.subplots(2, 2, figsize=(13, 9.5))

    for case, (label, style, colour) in FULL_LOAD.items():
        h = [r[0] for r in runs[case]]
        q = [-r[1] for r in runs[case]]
        p, limit = order_and_limit(q)
        a.plot(h, q, style, color=colour, label=label)
        a.axhline(limit, color=colour, ls=":", lw=1)
        if p is not None:
            err = [abs(v - limit) / limit for v in q]
            slope = fitted_slope(h[-3:], err[-3:])
            b.loglog(h, [100 * e for e in err], style, color=colour,
                     label=f"full load, {label.split(' (')[0]}: slope {slope:.2f}")
    a.set_xlabel("spacing h (mm)")
    a.set_ylabel("sag of the free-face centre (mm)")
    a.set_title("Full load (≈ 27% strain); dotted: extrapolated")
    a.legend(fontsize=8)
    a.grid(True, which="both", alpha=0.3)

    for case, (label, style, colour) in SMALL_LOAD.items():
        h = [r[0] for r in runs[case]]
        q = [-r[1] / r[2] for r in runs[case]]  # per unit gravity scale
        p, limit = order_and_limit(q)
        c.plot(h, q, style, color=colour, label=label)
        if p is None:
            continue  # converged to the solver's tolerance: no order, no extrapolation
        c.axhline(limit, color=colour, ls=":", lw=1)
        err = [abs(v - limit) / limit for v in q]
        slope = fitted_slope(h[-3:], err[-3:])
        b.loglog(h, [100 * e for e in err], style, color=colour, alpha=0.6, ms=4,
                 label=f"small load, {label.split(' (')[0]}: slope {slope:.2f}")
    hs = sorted({r[0] for r in runs["nh_nu0.45_g1"]})
    b.loglog(hs, [5 * v for v in hs], "k:", lw=1, label="slope 1")
    b.set_xlabel("spacing h (mm)")
    b.set_ylabel("|q_h − q_∞| / |q_∞| (%)")
    b.set_title("Error vs extrapolated limit (fit: 3 finest)")
    b.set_ylim(top=1e3)
    b.legend(loc="upper left", fontsize=7)
    b.grid(True, which="both", alpha=0.3)

    c.set_xlabel("spacing h (mm)")
    c.set_ylabel("sag per unit gravity scale (mm)")
    c.set_title("Small load (0.03 g, ≈ 1% strain); dotted: extrapolated")
    c.legend(fontsize=8)
    c.grid(True, which="both", alpha=0.3)

    # linear springs against neo-Hookean at their ν = 1/4, extrapolated, as a function of strain
    strain, departure = [], []
    for g in sorted({r[2] for case in runs for r in runs[case]}):
        lin, nh = runs.get(f"linear_nu0.25_g{g:g}"), runs.get(f"nh_nu0.25_g{g:g}")
        if not lin or not nh:
            continue
        _, lim_lin = order_and_limit([r[1] for r in lin])
        _, lim_nh = order_and_limit([r[1] for r in nh])
        strain.append(100 * nh[-1][3])
        departure.append(100 * (lim_lin / lim_nh - 1))
    d.semilogx(strain, departure, "o-", color="C2", label="extrapolated (h → 0)")
    d.axhline(0, color="k", lw=0.8)
    for x, y in zip(strain, departure):
        d.annotate(f"{y:+.2f}%", (x, y), textcoords="offset points", xytext=(6, 4), fontsize=8)
    d.set_xlabel("peak axial strain on the axis, neo-Hookean (%)")
    d.set_ylabel("linear springs / neo-Hookean ν 0.25 − 1 (%)")
    d.set_title("Linear springs vs neo-Hookean (same E, ν = 1/4)")
    d.legend(fontsize=8)
    d.grid(True, which="both", alpha=0.3)

    for ax in (a, b, c):
        ax.set_xscale("log", base=2)
        ax.set_xticks(hs, [f"{v:g}" for v in hs])
        ax.minorticks_off()
    fig.suptitle("3 cm neo-Hookean cube (E = 1 kPa, ρ = 1000 kg/m³) hanging from its held top face")
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
