#!/usr/bin/env python3
"""history.png of a `voxbreast fit` folder: cost and RMS displacement error against iteration,
and each region's modulus (up to 12 regions). Usage: python3 scripts/plot_fit.py FIT_DIR
Exit 77 when matplotlib is missing (the fit still succeeds)."""
import csv
import os
import sys


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    folder = sys.argv[1]
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return 77
    with open(os.path.join(folder, "history.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        print("plot_fit: history.csv has no rows", file=sys.stderr)
        return 1
    it = [int(r["iteration"]) for r in rows]
    moduli = [k for k in rows[0] if k.startswith("E_") and k.endswith("_pa")]
    panels = 3 if moduli and len(moduli) <= 12 else 2
    fig, axes = plt.subplots(1, panels, figsize=(4.2 * panels, 3.4))
    axes[0].semilogy(it, [max(float(r["cost"]), 1e-300) for r in rows], "o-")
    axes[0].set_xlabel("iteration")
    axes[0].set_ylabel("cost")
    axes[0].set_title("cost (data + regularisation)")
    axes[1].plot(it, [float(r["rms_mm"]) for r in rows], "o-", label="RMS |sim − obs|")
    axes[1].set_xlabel("iteration")
    axes[1].set_ylabel("mm")
    axes[1].set_title("displacement error")
    axes[1].legend()
    if panels == 3:
        for k in moduli:
            axes[2].semilogy(it, [float(r[k]) / 1e3 for r in rows], "o-", label=k[2:-3])
        axes[2].set_xlabel("iteration")
        axes[2].set_ylabel("E (kPa)")
        axes[2].set_title("region moduli")
        axes[2].legend(fontsize=7)
    for a in axes:
        a.grid(True, alpha=0.3)
    fig.tight_layout()
    out = os.path.join(folder, "history.png")
    tmp = os.path.join(folder, ".history.png.tmp.png")
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, out)  # atomic, like every output
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
