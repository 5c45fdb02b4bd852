#!/usr/bin/python3
"""Plots plate compression of a hyperelastic cube (nominal stress against stretch) from the CSV
that the level sweep writes (docs/results/plate_compression_levels.csv; how it was produced is in
docs/VALIDATION.md).

    /usr/bin/python3 scripts/plot_plate_compression.py docs/results/plate_compression_levels.csv \
        docs/img/plate_compression.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

NAMES = {"nh": "neo-Hookean", "ogden": "Ogden, 2 terms"}


def main(csv_path, png_path):
    rows = list(csv.DictReader(open(csv_path)))
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    for law, colour in (("nh", "C0"), ("ogden", "C1")):
        r = [x for x in rows if x["law"] == law]
        lam = [float(x["stretch"]) for x in r]
        a.plot(lam, [-float(x["closed_form_pa"]) / 1e3 for x in r], "-", color=colour,
               label=f"{NAMES[law]}: closed form")
        a.plot(lam, [-float(x["nominal_stress_double_pa"]) / 1e3 for x in r], "o", color=colour,
               label=f"{NAMES[law]}: lattice, 10³")
        b.plot(lam, [100 * (float(x["ratio_double"]) - 1) for x in r], "o-", color=colour,
               label=f"{NAMES[law]} (double)")
        b.plot(lam, [100 * (float(x["ratio_float"]) - 1) for x in r], "x", color=colour, ms=9,
               label=f"{NAMES[law]} (float)")
    a.set_xlabel("stretch λ (plate gap / initial gap)")
    a.set_ylabel("nominal stress (kPa)")
    a.set_title("Cube between frictionless plates, ν = 0.495")
    a.invert_xaxis()
    a.legend(fontsize=8)
    a.grid(True, alpha=0.3)
    for bound in (-3, 3):
        b.axhline(bound, color="r", ls="--")
    b.set_xlabel("stretch λ")
    b.set_ylabel("lattice / closed form − 1 (%)")
    b.set_title("Error at every load level (bound ±3%)")
    b.invert_xaxis()
    b.legend(fontsize=8)
    b.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
