#!/usr/bin/env python3
"""The palpation paper's truth-cube study (000_cec263896ad2aa44.txt; docs/VALIDATION.md,
"Probing: palpation and indenters"): an 8 cm cube of adipose (500 Pa) with a spherical tumour (10 kPa), a line
of presses across the top (every 8 mm). Sweeps the tumour diameter (1–4 cm, centre 2.6 cm deep) and depth
(1.8–3.8 cm, diameter 2 cm), each against the tumour-free cube; reports the force-profile excess,
its FWHM, and the press depth at given forces with and without the tumour.

  python3 scripts/palpation_sweep.py --voxbreast build/apps/voxbreast --out out/palpation_sweep
Writes OUT/table.md, OUT/sweep.csv and docs-ready PNGs (OUT/palpation_width.png,
OUT/palpation_profiles.png). Takes about 15 minutes on 2 CPU cores at the default 4 mm spacing.
"""
import argparse
import csv
import os
import shlex
import subprocess
import sys

from probe_csv import fwhm, read_csv


SCENE = """[model]
spacing = {h}
[[model.shape]]
kind = "box"
min = [0, 0, 0]
max = [0.08, 0.08, 0.08]
label = "adipose"
{tumour}
[materials.adipose]
E = 500.0
density = 950.0
[materials.tumour]
E = 10000.0
density = 1050.0
[solver]
integrator = "relaxation"
precision = "float"
check_every = 50
[anchor.base]
kind = "halfspace"
point = [0, 0, {h}]
normal = [0, 0, -1]
[[indenter]]
kind = "sphere"
radius = 0.008
[probe]
from = [{x0}, {y}, 0.2]
to = [{x1}, {y}, 0.2]
presses = {presses}
direction = [0, 0, -1]
depth = {press_depth}
steps = {steps}
at_force = {forces}
[stop]
equilibrium = 1e-5
max_steps = 40000
"""
TUMOUR = """[[model.shape]]
kind = "sphere"
center = [{c}, {c}, {z}]
radius = {r}
label = "tumour"
"""
FORCES = [0.002, 0.004, 0.008]


def run(vox, out, name, h, diameter, depth, pitch, device, press_depth):
    folder = os.path.join(out, name)
    os.makedirs(folder, exist_ok=True)
    c = 0.040 + h / 2  # the centre column: on an element column
    tumour = TUMOUR.format(c=c, z=0.08 - depth, r=diameter / 2) if diameter > 0 else ""
    presses = int(round(0.064 / pitch)) + 1
    steps = max(1, int(round(press_depth / 0.001)))  # 1 mm increments
    scene = SCENE.format(h=h, tumour=tumour, x0=c - 0.032, x1=c + 0.032, y=c, presses=presses, forces=FORCES,
                         press_depth=press_depth, steps=steps)
    path = os.path.join(folder, "scene.toml")
    if not os.path.exists(os.path.join(folder, "probe_profile.csv")):  # done already (or fetched): reuse
        with open(path, "w") as f:
            f.write(scene)
        cmd = shlex.split(vox) + ["probe", path, "--out", folder, "--quiet"] + (["--device", device] if device else [])
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    rows = read_csv(os.path.join(folder, "probe_profile.csv"))
    folded = [r["position_mm"] for r in rows if r.get("inverted") == "1"]
    if folded:  # the lattice folded under the ball: those forces are not the tissue's (docs/PROBING.md)
        print(f"warning: {name}: {len(folded)} presses folded the lattice (at {', '.join(folded)} mm)", file=sys.stderr)
    s = [float(r["position_mm"]) - 32 for r in rows]  # 0 above the tumour
    return s, [float(r["peak_force_n"]) for r in rows], rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--voxbreast", default="build/apps/voxbreast", help="command that runs voxbreast")
    ap.add_argument("--device", default="", help="voxbreast --device (default: $VOXBREAST_DEVICE)")
    ap.add_argument("--no-plots", action="store_true", help="tables only (no matplotlib needed)")
    ap.add_argument("--out", default="out/palpation_sweep")
    ap.add_argument("--spacing", type=float, default=0.004, help="lattice spacing (m)")
    ap.add_argument("--pitch", type=float, default=0.008, help="distance between presses (m)")
    ap.add_argument("--depth", type=float, default=0.004, help="press depth (m), in 1 mm increments")
    a = ap.parse_args()
    h = a.spacing
    s, base, base_rows = run(a.voxbreast, a.out, "free", h, 0, 0, a.pitch, a.device, a.depth)
    mid = len(s) // 2
    cases = [("diameter", d, 0.026) for d in (0.010, 0.016, 0.020, 0.024, 0.032, 0.040)]
    cases += [("depth", 0.020, z) for z in (0.018, 0.022, 0.030, 0.034, 0.038)]
    results = []
    profiles = {}
    for kind, d, z in cases:
        name = f"d{1e3 * d:.0f}_z{1e3 * z:.0f}"
        print(f"running {name}", file=sys.stderr)
        s, f, rows = run(a.voxbreast, a.out, name, h, d, z, a.pitch, a.device, a.depth)
        excess = [x - y for x, y in zip(f, base)]
        depth_t = [float(rows[mid][f"depth_at_{F:g}N_mm"] or "nan") for F in FORCES]
        depth_b = [float(base_rows[mid][f"depth_at_{F:g}N_mm"] or "nan") for F in FORCES]
        results.append({"sweep": kind, "diameter_mm": 1e3 * d, "depth_mm": 1e3 * z, "peak_excess_n": max(excess),
                        "peak_excess_pct": 100 * max(excess) / base[mid], "fwhm_mm": fwhm(s, excess),
                        "folded_presses": sum(r.get("inverted") == "1" for r in rows),
                        **{f"ddepth_{1e3 * F:g}mN_mm": b - t for F, b, t in zip(FORCES, depth_b, depth_t)}})
        profiles[name] = (s, excess)
    keys = list(results[0].keys())
    with open(os.path.join(a.out, "sweep.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, keys)
        w.writeheader()
        w.writerows(results)
    lines = ["| sweep | tumour diameter (mm) | centre depth (mm) | peak force excess (mN) | excess (%) | FWHM (mm) | "
             + " | ".join(f"depth difference at {1e3 * F:g} mN (mm)" for F in FORCES) + " | folded presses |",
             "|" + "---|" * (7 + len(FORCES))]
    for r in results:
        lines.append(f"| {r['sweep']} | {r['diameter_mm']:.0f} | {r['depth_mm']:.0f} | {1e3 * r['peak_excess_n']:.3f} | "
                     f"{r['peak_excess_pct']:.1f} | {r['fwhm_mm']:.1f} | "
                     + " | ".join(f"{r[f'ddepth_{1e3 * F:g}mN_mm']:.3f}" for F in FORCES) + f" | {r['folded_presses']} |")
    table = "\n".join(lines) + "\n"
    with open(os.path.join(a.out, "table.md"), "w") as fh:
        fh.write(table)
    print(table)
    if a.no_plots:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    dia = [r for r in results if r["sweep"] == "diameter"]
    dep = [r for r in results if r["sweep"] == "depth"]
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.6))
    ax[0].plot([r["diameter_mm"] for r in dia], [r["fwhm_mm"] for r in dia], "o-")
    ax[0].set_xlabel("tumour diameter (mm), centre 26 mm deep")
    ax[0].set_ylabel("FWHM of the force excess (mm)")
    ax[1].plot([r["depth_mm"] for r in dep], [r["fwhm_mm"] for r in dep], "s-", label="FWHM")
    ax[1].set_xlabel("tumour centre depth (mm), diameter 20 mm")
    ax[1].set_ylabel("FWHM (mm)")
    for x in ax:
        x.grid(alpha=0.3)
    fig.suptitle("palpation cube: width of the force-profile excess")
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "palpation_width.png"), dpi=120)
    fig, ax = plt.subplots(figsize=(6, 4))
    for r in dia:
        name = f"d{r['diameter_mm']:.0f}_z{r['depth_mm']:.0f}"
        ax.plot(*profiles[name], "o-", ms=3, label=f"D = {r['diameter_mm']:.0f} mm")
    ax.set_xlabel("position along the line, 0 above the tumour (mm)")
    ax.set_ylabel("force excess over the tumour-free cube (N)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "palpation_profiles.png"), dpi=120)
    print(f"wrote {a.out}/table.md, sweep.csv, palpation_width.png, palpation_profiles.png", file=sys.stderr)


if __name__ == "__main__":
    main()
