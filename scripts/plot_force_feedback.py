#!/usr/bin/python3
"""Plots for the haptic probe and fit-curve (docs/HAPTICS.md, docs/FIT_CURVE.md).

    /usr/bin/python3 scripts/plot_force_feedback.py haptic out/haptic/haptic.csv docs/img/haptic_press.png
    /usr/bin/python3 scripts/plot_force_feedback.py fit out/fit/fit_curve.csv docs/img/fit_curve_cube.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def plot_haptic(path, out):
    r = rows(path)
    t = [float(x["time_s"]) for x in r]
    fig, (ax_f, ax_z) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    ax_f.plot(t, [float(x["fz_n"]) for x in r], lw=0.8, label="force output (1 kHz)")
    # where a deformation update arrived
    ups = [i for i in range(1, len(r)) if r[i]["updates"] != r[i - 1]["updates"]]
    ax_f.plot([t[i] for i in ups], [float(r[i]["fz_n"]) for i in ups], "o", ms=3, label="first output after an update")
    ax_f.set_ylabel("force on probe, z (N)")
    ax_f.legend(loc="upper left", fontsize=8)
    ax_z.plot(t, [float(x["z_mm"]) for x in r], lw=0.8)
    ax_z.set_ylabel("probe centre z (mm)")
    ax_z.set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def plot_fit(path, out):
    r = rows(path)
    d = [float(x["displacement_mm"]) for x in r]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(d, [float(x["measured_n"]) for x in r], "ko", label="measured")
    ax.plot(d, [float(x["start_n"]) for x in r], "--", label="start")
    ax.plot(d, [float(x["fitted_n"]) for x in r], "-", label="fitted")
    ax.set_xlabel("displacement (mm)")
    ax.set_ylabel("force (N)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    kind, path, out = sys.argv[1:4]
    {"haptic": plot_haptic, "fit": plot_fit}[kind](path, out)
    print("wrote", out)
