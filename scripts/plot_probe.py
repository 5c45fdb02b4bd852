#!/usr/bin/env python3
"""Plots a `voxbreast probe` output folder: force–displacement curves of every press
(probe_curves.png) and the force profile along the line (probe_profile.png). With --baseline DIR
(the same probe on the tumour-free model) the profile panel shows the force excess and its FWHM.

  python3 scripts/plot_probe.py out/palpation [--baseline out/palpation_free]
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from probe_csv import fwhm, read_csv  # noqa: E402


def profile(folder):
    rows = read_csv(os.path.join(folder, "probe_profile.csv"))
    return [float(r["position_mm"]) for r in rows], [float(r["peak_force_n"]) for r in rows]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder")
    ap.add_argument("--baseline", help="probe output of the tumour-free model")
    ap.add_argument("--out", help="folder for the PNGs (default: the probe folder)")
    a = ap.parse_args()
    out = a.out or a.folder

    curves = read_csv(os.path.join(a.folder, "probe_curves.csv"))
    fig, ax = plt.subplots(figsize=(6, 4))
    presses = sorted({int(r["press"]) for r in curves})
    cmap = plt.get_cmap("viridis")
    for i, p in enumerate(presses):
        rows = [r for r in curves if int(r["press"]) == p]
        ax.plot([float(r["depth_mm"]) for r in rows], [float(r["press_force_n"]) for r in rows],
                color=cmap(i / max(1, len(presses) - 1)), label=f"{float(rows[0]['position_mm']):.0f} mm")
    ax.set_xlabel("press depth (mm)")
    ax.set_ylabel("reaction force (N)")
    ax.set_title("force–displacement per press")
    if len(presses) <= 10:
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "probe_curves.png"), dpi=120)

    s, f = profile(a.folder)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(s, f, "o-", label="peak force")
    if a.baseline:
        sb, fb = profile(a.baseline)
        ax.plot(sb, fb, "s--", label="tumour-free")
        excess = [x - y for x, y in zip(f, fb)]
        ax2 = ax.twinx()
        ax2.plot(s, excess, "r^-", label="excess")
        ax2.set_ylabel("force excess (N)", color="r")
        ax.set_title(f"force profile; excess FWHM {fwhm(s, excess):.1f} mm")
    else:
        ax.set_title("force profile along the line of presses")
    ax.set_xlabel("position along the line (mm)")
    ax.set_ylabel("force at full depth (N)")
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "probe_profile.png"), dpi=120)
    print(f"wrote {out}/probe_curves.png and {out}/probe_profile.png")


if __name__ == "__main__":
    main()
