#!/usr/bin/python3
"""Sanity checks of a `voxbreast bench` run (bench.csv + bench.json), used by the bench_quick test.

    /usr/bin/python3 tests/apps/check_bench.py OUT_DIR

Asserts what must hold whatever the device: every value finite (or absent where it does not
apply), the references agree with themselves, real runs differ from them by a little, the error
grows as the resolution coarsens, double precision gets closer to the reference than float once
the tolerance is below float's round-off floor, the automatic step is stable and 4x it is
reported unstable for springs, the volume constraint holds the volume, and the column's field
error is consistent with its closed-form sag (computed without the field sampling).
Exit 0 when every check passes, 1 otherwise (each failure printed).
"""
import csv
import json
import math
import os
import sys
from collections import defaultdict

failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL", what)


def num(row, key):
    """The value of a numeric column; None where it does not apply (empty)."""
    text = row[key]
    return None if text == "" else float(text)


def finite(row, key):
    v = num(row, key)
    return v is not None and math.isfinite(v)


def label(r):
    return (f'{r["scene"]} {r["part"]} {r["law"]} {r["integrator"]} {r["precision"]} d{r["downsample"]} '
            f'dt*{r["dt_factor"]} vol {r["volume"]} tol {r["tolerance"]}')


def main(out_dir):
    rows = list(csv.DictReader(open(os.path.join(out_dir, "bench.csv"))))
    doc = json.load(open(os.path.join(out_dir, "bench.json")))
    check(len(rows) > 0 and len(rows) == len(doc["results"]), "bench.csv and bench.json hold the same rows")
    for key in ("device", "git_commit", "date", "scenes", "reference"):
        check(key in doc, f"bench.json has '{key}'")

    # --- every value: finite where it applies, absent where it does not
    for j in doc["results"]:
        for k, v in j.items():
            if isinstance(v, float):
                check(math.isfinite(v), f"{k} finite in bench.json")
    measured = ("elements", "spacing_mm", "dt_s", "auto_dt_s", "steps", "simulated_s", "wall_s", "time_per_step_ms",
                "steps_per_s", "ns_per_element_step", "device_bytes_per_element", "max_displacement_mm",
                "error_max_mm", "error_rms_mm", "volume_change", "volume_error")
    for r in rows:
        check(r["status"] in ("ok", "not_converged", "unstable"), f"{label(r)}: status {r['status']} {r['message']}")
        if r["status"] in ("ok", "not_converged"):
            for k in measured:
                check(finite(r, k), f"{label(r)}: {k} finite ({r[k]!r})")
            if all(finite(r, k) for k in measured):
                check(num(r, "steps") > 0 and num(r, "wall_s") > 0 and num(r, "time_per_step_ms") > 0,
                      f"{label(r)}: positive steps, wall time, time per step")
                check(abs(num(r, "steps_per_s") * num(r, "time_per_step_ms") / 1e3 - 1) < 1e-6,
                      f"{label(r)}: steps/s is 1 / time per step")
                check(20 <= num(r, "device_bytes_per_element") <= 5000,
                      f"{label(r)}: device bytes per element {r['device_bytes_per_element']} plausible")
                check(0 <= num(r, "error_rms_mm") <= num(r, "error_max_mm"), f"{label(r)}: 0 <= RMS error <= max error")
                check(num(r, "volume_error") >= 0, f"{label(r)}: volume error >= 0")
                check(num(r, "max_displacement_mm") > 0, f"{label(r)}: the model moved")
        else:
            check("unstable" in r["message"], f"{label(r)}: the instability message is kept")
            check(r["error_max_mm"] == "" and r["error_rms_mm"] == "", f"{label(r)}: an unstable run has no error")

    # --- references: one per scene, law and volume; exact against themselves
    refs = {(r["scene"], r["law"], r["volume"]): r for r in rows if r["part"] == "reference"}
    for key, ref in refs.items():
        check(ref["status"] == "ok", f"{label(ref)}: the reference reached equilibrium")
        check(ref["precision"] == "double" and ref["downsample"] == "1", f"{label(ref)}: reference is double, finest")
        check(num(ref, "error_max_mm") == 0, f"{label(ref)}: a reference sampled at its own elements is itself")
    runs = [r for r in rows if r["part"] != "reference"]
    for r in runs:
        check((r["scene"], r["law"], r["volume"]) in refs, f"{label(r)}: has its reference")

    # --- a real run at the reference's resolution differs from it, by little
    for r in runs:
        ref = refs.get((r["scene"], r["law"], r["volume"]))
        if ref is None or r["status"] != "ok" or r["downsample"] != "1":
            continue
        check(num(r, "error_rms_mm") > 0, f"{label(r)}: nonzero error against the reference (else the measure is blind)")
        check(num(r, "error_max_mm") < 0.01 * num(ref, "max_displacement_mm"),
              f"{label(r)}: error {r['error_max_mm']} mm within 1% of the displacement at full resolution")

    # --- error grows as the resolution coarsens (same knobs otherwise)
    by_scene = defaultdict(list)
    for r in runs:
        if r["part"] in ("base", "resolution") and r["status"] == "ok":
            by_scene[(r["scene"], r["law"], r["integrator"], r["precision"], r["dt_factor"], r["volume"])].append(r)
    resolution_sweeps = 0
    for key, group in by_scene.items():
        group.sort(key=lambda r: int(r["downsample"]))
        if len(group) < 2:
            continue
        resolution_sweeps += 1
        for fine, coarse in zip(group, group[1:]):
            check(num(fine, "elements") > num(coarse, "elements"), f"{label(coarse)}: fewer elements than {label(fine)}")
            check(num(fine, "error_rms_mm") < num(coarse, "error_rms_mm"),
                  f"{label(coarse)}: RMS error {coarse['error_rms_mm']} above the finer {fine['error_rms_mm']} mm")
            check(num(fine, "error_max_mm") < num(coarse, "error_max_mm"),
                  f"{label(coarse)}: max error {coarse['error_max_mm']} above the finer {fine['error_max_mm']} mm")
    check(resolution_sweeps > 0, "some resolution sweep to check")

    # --- column: closed form (computed from the top layer, not by the field sampling)
    sag = {s["name"]: s.get("closed_form_sag_mm") for s in doc["scenes"]}
    for r in runs:
        ref = refs.get((r["scene"], r["law"], r["volume"]))
        if r["scene"] != "column" or ref is None or r["status"] != "ok" or not finite(r, "closed_form_error"):
            continue
        top_difference = abs(num(r, "closed_form_error") - num(ref, "closed_form_error")) * sag["column"]
        check(num(r, "error_max_mm") >= 0.5 * top_difference,
              f"{label(r)}: max error {r['error_max_mm']} mm at least half the top-layer sag difference {top_difference:.3g} mm")
    for key, group in by_scene.items():
        if key[0] == "column" and key[1] == "linear" and len(group) > 1:
            cf = [abs(num(r, "closed_form_error")) for r in group]
            check(cf == sorted(cf), f"column {key}: closed-form error shrinks with resolution {cf}")
    linear_ref = refs.get(("column", "linear", "off"))
    if linear_ref:
        check(abs(num(linear_ref, "closed_form_error")) < 0.15,
              f"column: linear springs within 15% of rho g L^2/(2E) (got {linear_ref['closed_form_error']})")

    # --- precision: at the tightest tolerance (below float's floor), double is closer to the
    # reference. (At a looser one double's distance from equilibrium can exceed float's round-off.)
    pairs = defaultdict(dict)
    tightest = {}
    for r in runs:
        if r["part"] == "tolerance":
            pairs[(r["scene"], r["law"], r["tolerance"])][r["precision"]] = r
            key = (r["scene"], r["law"])
            tightest[key] = min(tightest.get(key, 1.0), float(r["tolerance"]))
    pairs = {k: p for k, p in pairs.items() if float(k[2]) == tightest[k[:2]]}
    check(len(pairs) > 0, "some tolerance pair (float, double) to compare")
    for key, p in pairs.items():
        if "float" in p and "double" in p:
            f, d = p["float"], p["double"]
            check(d["status"] == "ok", f"{label(d)}: double reaches the tight tolerance")
            check(finite(f, "error_rms_mm") and finite(d, "error_rms_mm")
                  and num(d, "error_rms_mm") < 0.5 * num(f, "error_rms_mm"),
                  f"{key}: double RMS error {d['error_rms_mm']} mm below half of float's {f['error_rms_mm']} mm")

    # --- time step: the automatic step and below are stable; 4x the step breaks springs
    for r in runs:
        if float(r["dt_factor"]) <= 1:
            check(r["status"] != "unstable", f"{label(r)}: stable at or below the automatic step")
        if r["scene"] == "column" and r["law"] == "linear" and float(r["dt_factor"]) == 4:
            check(r["status"] == "unstable", f"{label(r)}: 4x the automatic step (2x the bound) is reported unstable")
    for r in runs:
        if r["part"] == "time_step" and float(r["dt_factor"]) == 0.5 and r["status"] == "ok":
            base = [b for b in runs if b["part"] == "base" and b["scene"] == r["scene"] and b["law"] == r["law"]]
            if base and base[0]["status"] == "ok":
                check(num(r, "steps") > num(base[0], "steps"), f"{label(r)}: half the step takes more steps")

    # --- volume constraint holds the enclosed volume; without it the column changes volume
    for r in runs:
        if r["volume"] == "on" and r["status"] == "ok":
            check(abs(num(r, "volume_change")) < 1e-4, f"{label(r)}: volume held ({r['volume_change']})")
    base_column = [r for r in runs if r["part"] == "base" and r["scene"] == "column" and r["status"] == "ok"]
    if base_column:
        check(abs(num(base_column[0], "volume_change")) > 1e-3, "column without the constraint changes volume")

    # --- scenes listed with the element counts the rows report
    for s in doc["scenes"]:
        for d, n in s["elements_by_downsample"].items():
            matching = [r for r in rows if r["scene"] == s["name"] and r["downsample"] == d]
            check(all(int(float(r["elements"])) == n for r in matching), f"{s['name']} d{d}: {n} elements in every row")

    print(f"{len(rows)} rows checked: {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
