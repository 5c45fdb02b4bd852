#!/usr/bin/python3
"""Markdown tables of a `voxbreast bench` study (for docs/BENCHMARKS.md).

    /usr/bin/python3 scripts/bench_study_table.py out/bench/bench.csv [SCENE ...]

Per scene: the references, the law x integrator x precision grid, and the one-factor-at-a-time
sweeps (resolution, time step, volume constraint, tolerance) around each base case.
"""
import csv
import sys


def g(x, digits=3):
    """A number with `digits` significant digits; '—' when absent."""
    if x == "":
        return "—"
    v = float(x)
    if v == 0:
        return "0"
    if abs(v) >= 1000:
        return f"{v:,.0f}"
    return f"{v:.{digits}g}"


def knobs(r):
    integ = {"symplectic_euler": "Euler", "heun": "Heun", "relaxation": "relaxation"}.get(r["integrator"], r["integrator"])
    out = f'{r["law"]}, {integ}, {r["precision"]}'
    if r["downsample"] != "1":
        out += f', downsample {r["downsample"]}'
    if float(r["dt_factor"]) != 1:
        out += f', dt × {float(r["dt_factor"]):g}'
    if r["volume"] == "on":
        out += ", volume on"
    if r["part"] in ("tolerance", "reference"):
        out += f', tol {float(r["tolerance"]):g}'
    return out


HEADER = ("| case | elements | steps | wall s | ms/step | B/element | max error mm | RMS error mm | "
          "ΔV/V % | ΔV error % | closed form |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")


def line(r):
    if r["status"] == "unstable":
        step = r["message"].split("unstable at step ")[1].split(" ")[0] if "unstable at step " in r["message"] else "?"
        return f'| {knobs(r)} | {int(float(r["elements"])):,} | **unstable** (step {step}) | | | | | | | | |'
    note = "" if r["status"] == "ok" else " (not converged)"
    cf = f'{100 * float(r["closed_form_error"]):+.1f}%' if r["closed_form_error"] else "—"
    dv = f'{100 * float(r["volume_change"]):+.3f}' if r["volume_change"] else "—"
    dve = g(str(100 * float(r["volume_error"])), 2) if r["volume_error"] else "—"
    return (f'| {knobs(r)}{note} | {int(float(r["elements"])):,} | {int(float(r["steps"])):,} | {g(r["wall_s"])} | '
            f'{g(r["time_per_step_ms"])} | {g(r["device_bytes_per_element"])} | {g(r["error_max_mm"], 2)} | '
            f'{g(r["error_rms_mm"], 2)} | {dv} | {dve} | {cf} |')


def main(path, scenes):
    rows = list(csv.DictReader(open(path)))
    for scene in scenes or list(dict.fromkeys(r["scene"] for r in rows)):
        sel = [r for r in rows if r["scene"] == scene]
        for title, parts in (("references", ("reference",)), ("law × integrator × precision", ("base", "grid")),
                             ("one factor at a time around the base case", ("resolution", "time_step", "volume", "tolerance"))):
            part_rows = [r for r in sel if r["part"] in parts]
            if not part_rows:
                continue
            print(f"\n**{scene}: {title}**\n\n{HEADER}")
            for r in part_rows:
                print(line(r))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
