#!/usr/bin/python3
"""Reads the runs of scripts/plate_compression_sweep.sh and writes the CSV that
scripts/plot_plate_compression.py plots: nominal stress over the body's area ((n − 1)·h)² against
the incompressible Ogden closed form (liver paper eq. 3), double and float, and the largest
float-vs-double difference in final displacement.

    /usr/bin/python3 scripts/plate_compression_table.py RESULTS_DIR OUT.csv
"""
import csv
import json
import sys

import h5py
import numpy as np

N, H = 10, 0.002
LAWS = {  # (μ_p, α_p) of the sweep's materials; neo-Hookean: μ = E/(2(1 + ν)), α = 2
    "nh": ([3000 / (2 * 1.495)], [2]),
    "ogden": ([1200, -300], [4, -2]),
}
STRETCHES = [0.95, 0.9, 0.85, 0.8, 0.75, 0.7, 0.65, 0.6, 0.55, 0.5]


def closed_form(law, lam):
    mu, alpha = LAWS[law]
    return sum(m * (lam ** (a - 1) - lam ** (-a / 2 - 1)) for m, a in zip(mu, alpha))


def run(results, name):
    summary = json.load(open(f"{results}/{name}/summary.json"))
    force = summary["indenters"][1]["reaction_force_n"][2]
    u = h5py.File(f"{results}/{name}/result.h5")["state/displacement_m"][:]
    return force / ((N - 1) * H) ** 2, u, summary["steps"]


def main(results, csv_path):
    with open(csv_path, "w", newline="") as out:
        w = csv.writer(out)
        w.writerow(["law", "stretch", "nominal_stress_double_pa", "closed_form_pa", "ratio_double",
                    "ratio_float", "float_vs_double_max_displacement_rel", "steps_double"])
        for law in LAWS:
            for lam in STRETCHES:
                pd, ud, steps = run(results, f"{law}_double_l{lam}")
                pf, uf, _ = run(results, f"{law}_float_l{lam}")
                exact = -closed_form(law, lam)  # compression: the plate is pushed back (+)
                rel = np.abs(uf - ud).max() / np.abs(ud).max()
                w.writerow([law, lam, f"{pd:.3f}", f"{exact:.3f}", f"{pd / exact:.5f}", f"{pf / exact:.5f}",
                            f"{rel:.3e}", steps])


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
