#!/usr/bin/python3
"""Plots the core validation numbers that the physics tests record (gtest XML properties).

    VOXBREAST_DEVICE=cpu build/tests/test_physics --gtest_output=xml:/tmp/physics.xml
    /usr/bin/python3 scripts/plot_validation.py /tmp/physics.xml docs/img/validation_core.png
"""
import sys
import xml.etree.ElementTree as ET

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def properties(xml_path):
    out = {}
    for prop in ET.parse(xml_path).iter("property"):
        out[prop.get("name")] = float(prop.get("value"))
    return out


def main(xml_path, png_path):
    p = properties(xml_path)
    fig, (a, b, c) = plt.subplots(1, 3, figsize=(13, 4))
    h = [5.0, 2.5]
    err = [100 * p["error_h5mm"], 100 * p["error_h2_5mm"]]
    a.loglog(h, err, "o-", label="lattice")
    a.axhline(10, color="r", ls="--", label="10% bound")
    a.set_xlabel("spacing h (mm)")
    a.set_ylabel("top displacement error vs 1-D column (%)")
    a.set_title("Column under self-weight (4×4×10 cm)")
    a.legend()
    a.grid(True, which="both", alpha=0.3)
    b.bar(["symplectic Euler", "Heun"], [100 * p["euler_max_energy_error"], 100 * p["heun_max_energy_error"]])
    b.set_ylabel("max |ΔE|/E over 5 periods (%)")
    b.set_title("Undamped oscillator, ω·dt = 0.1")
    c.bar(["error ratio\nwhen dt halves:\nEuler", "Heun"], [p["euler_ratio_dt_halved"], p["heun_ratio_dt_halved"]])
    c.axhline(2, color="gray", ls=":", label="1st order (2×)")
    c.axhline(8, color="k", ls="--", label="Heun theory (8×)")
    c.set_title("Energy error convergence")
    c.legend()
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
