#!/usr/bin/env python3
"""Finite-element cross-check of VoxBreast: runs the cases of cases.py through
`voxbreast simulate` and through FEniCSx (fe_solve.py), and tabulates the errors.

Usage:
  python3 scripts/fe_reference/crosscheck.py --voxbreast build/apps/voxbreast --out out/fe \
      [--cases cube_sag,hemisphere_axial] [--spacings 4,2,1] [--precisions double,float] \
      [--fe-json out/fe/fe_reference.json] [--bounds tests/validation/fe_bounds.json] [--quick]

For each case the FE answer is computed on a sequence of meshes (the convergence study) and
extrapolated (Richardson, with the order observed on the three finest levels); the comparison
uses the extrapolated value, or the finest when fewer than three levels converge monotonically.
A case whose FE Newton solve did not converge on every level is not compared: the driver says
so and exits non-zero. Writes fe_reference.json (the study), crosscheck.csv (one row per
VoxBreast run) and prints the table with the observed order of VoxBreast's error in h.
--bounds checks each error against its recorded bound and exits 1 when one is exceeded.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cases import all_cases  # noqa: E402

# FE levels per case kind: full study and the quick CI version.
FE_LEVELS = {
    "CubeSag": {"full": [3, 6, 12], "quick": [3, 6]},
    "Hemisphere": {"full": [1, 2], "quick": [1, 2]},
    "ConfinedCompression": {"full": [1, 2], "quick": [1]},
}

MAX_FE_CELLS = 3000  # Q2 hexahedra: about 75k unknowns, a minute of a direct solve on 2 shared cores


def fe_study(case, h, quick):
    import fe_solve
    kind = type(case).__name__
    levels = FE_LEVELS[kind]["quick" if quick else "full"]
    rows = []
    for level, ijk, hf, r, kw in case.fe_problems(h, levels):
        body = fe_solve.Body(ijk, hf, r)
        if body.n_cells > MAX_FE_CELLS and rows:
            print(f"  FE {case.name} h={h*1e3:g} mm level {level}: {body.n_cells} hexahedra, above "
                  f"{MAX_FE_CELLS}: not solved (the study stops at level {rows[-1]['level']})", flush=True)
            break
        out = fe_solve.solve(body, case.fe_materials(), case.fe_material, rho_of=case.fe_density, **kw)
        out["level"] = level
        out["value"] = case.from_fe(out) if out["converged"] else None
        rows.append(out)
        print(f"  FE {case.name} h={h*1e3:g} mm level {level}: {out['value']} "
              f"({'converged' if out['converged'] else 'NOT converged'}, {out['dofs']} dofs, "
              f"{out['newton_iterations']} Newton its, {out['fe_time_s']:.1f} s)", flush=True)
    converged = all(r["converged"] for r in rows)
    values = [r["value"] for r in rows]
    study = {"levels": rows, "converged": converged, "quantity": case.quantity}
    if converged:
        ratio = levels[-1] / levels[-2] if len(levels) > 1 else 2.0
        limit, order = fe_solve.richardson(values, ratio)
        study.update(limit=limit, order=order, finest=values[-1],
                     fe_change_last_level=(values[-1] - values[-2]) / abs(values[-1]) if len(values) > 1 else None)
    if hasattr(case, "closed_form_mN"):
        study["closed_form"] = case.closed_form_mN()
        study["limit"] = study["closed_form"]
    return study


def run_voxbreast(binary, case, h, law, precision, outdir, max_steps, reuse):
    tol = 1e-9 if precision == "double" else case.float_tol
    name = f"{case.name}_h{h*1e3:g}_{law}_{precision}"
    d = os.path.join(outdir, "runs", name)
    os.makedirs(d, exist_ok=True)
    scene = os.path.join(d, "scene.toml")
    text = case.scene(h, law, precision, tol, max_steps)
    summary_path = os.path.join(d, "out", "summary.json")
    stamp = os.path.join(d, "binary.txt")
    key = f"{os.path.realpath(binary)} {os.path.getmtime(binary)}\n"
    if reuse and os.path.exists(summary_path) and os.path.exists(stamp) and open(scene).read() == text \
            and open(stamp).read() == key:
        proc, wall = None, None  # the same scene and binary ran before: reuse its summary
    else:
        with open(scene, "w") as f:
            f.write(text)
        if os.path.exists(summary_path):
            os.remove(summary_path)
        t0 = time.time()
        proc = subprocess.run([binary, "simulate", scene, "--out", os.path.join(d, "out"), "--quiet"],
                              capture_output=True, text=True)
        wall = time.time() - t0
        with open(stamp, "w") as f:
            f.write(key)
    if not os.path.exists(summary_path):
        return {"name": name, "error": proc.stderr.strip()[-400:] or f"exit {proc.returncode}", "wall_s": wall}
    with open(summary_path) as f:
        s = json.load(f)
    return {"name": name, "value": case.from_summary(s), "converged": bool(s["converged"]),
            "steps": s["steps"], "elements": s.get("elements"), "wall_s": wall,
            "exit": proc.returncode if proc else 0, "mass_kg": (s.get("model") or {}).get("total_mass_kg")}


def observed_orders(errors):
    """Observed order between consecutive spacings (halved): log2(e(2h)/e(h))."""
    out = {}
    hs = sorted(errors, reverse=True)
    for a, b in zip(hs, hs[1:]):
        ea, eb = errors[a], errors[b]
        if ea and eb and ea * eb > 0 and abs(a / b - 2) < 1e-9:
            out[b] = math.log(abs(ea / eb), 2)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--voxbreast", default="build/apps/voxbreast")
    ap.add_argument("--out", required=True)
    ap.add_argument("--cases", default=",".join(all_cases()))
    ap.add_argument("--spacings", default="4,2,1", help="mm")
    ap.add_argument("--precisions", default="double,float")
    ap.add_argument("--laws", default="", help="restrict to these laws (default: each case's)")
    ap.add_argument("--fe-json", default="", help="reuse (and extend) this FE study instead of recomputing")
    ap.add_argument("--fe-only", action="store_true")
    ap.add_argument("--quick", action="store_true", help="coarse FE levels (CI)")
    ap.add_argument("--bounds", default="", help="JSON of error bounds (percent) to check")
    ap.add_argument("--max-steps", type=int, default=50000)
    ap.add_argument("--reuse", action="store_true", help="reuse a run whose scene and binary are unchanged")
    ap.add_argument("--csv", default="", help="CSV path (default OUT/crosscheck.csv)")
    args = ap.parse_args()

    cases = all_cases()
    names = [c for c in args.cases.split(",") if c]
    for n in names:
        if n not in cases:
            sys.exit(f"crosscheck: unknown case '{n}' (cases: {', '.join(cases)})")
    spacings = [float(s) * 1e-3 for s in args.spacings.split(",")]
    os.makedirs(args.out, exist_ok=True)
    fe_path = args.fe_json or os.path.join(args.out, "fe_reference.json")
    fe = {}
    if args.fe_json and os.path.exists(args.fe_json):
        with open(args.fe_json) as f:
            fe = json.load(f)

    # FE studies (one per body: per spacing where the hull depends on h).
    for n in names:
        case = cases[n]
        for h in (spacings if case.fe_body_depends_on_h else [None]):
            key = f"{n}@{h*1e3:g}mm" if h else n
            if key in fe and fe[key].get("quick", False) == args.quick:
                continue
            fe[key] = fe_study(case, h if h else spacings[0], args.quick)
            fe[key]["quick"] = args.quick
            fe[key]["description"] = case.description
            with open(fe_path, "w") as f:
                json.dump(fe, f, indent=1)
    if args.fe_only:
        return 0

    refused = []
    rows = []
    for n in names:
        case = cases[n]
        laws = [l for l in case.laws if not args.laws or l in args.laws.split(",")]
        for h in spacings:
            key = f"{n}@{h*1e3:g}mm" if case.fe_body_depends_on_h else n
            study = fe[key]
            if not study["converged"]:
                refused.append(key)
                print(f"crosscheck: {key}: the FE Newton solve did not converge; not compared", file=sys.stderr)
                continue
            ref = study["limit"]
            for law in laws:
                for prec in args.precisions.split(","):
                    if prec == "float" and h < case.float_min_h - 1e-12:
                        continue
                    r = run_voxbreast(args.voxbreast, case, h, law, prec, args.out, args.max_steps, args.reuse)
                    row = {"case": n, "quantity": case.quantity, "h_mm": h * 1e3, "law": law,
                           "precision": prec, "fe_reference": ref, "fe_finest": study.get("finest"),
                           "fe_order": study.get("order"), **{k: r.get(k) for k in
                           ("value", "converged", "steps", "elements", "wall_s", "mass_kg")}}
                    if "error" in r or not r.get("converged"):
                        row["error_pct"] = None
                        print(f"crosscheck: {r['name']}: VoxBreast did not converge: {r.get('error', '')}", file=sys.stderr)
                    else:
                        row["error_pct"] = 100.0 * (r["value"] - ref) / abs(ref)
                    rows.append(row)
                    print(f"{n:22s} h={h*1e3:g} mm {law:11s} {prec:6s} VoxBreast {row['value'] if row['value'] is not None else float('nan'):.5g} "
                          f"FE {ref:.5g}  error {row['error_pct'] if row['error_pct'] is not None else float('nan'):+.2f}%  "
                          f"({r.get('steps')} steps, {r.get('wall_s') or 0:.1f} s)", flush=True)

    # Observed order of VoxBreast's error per case/law/precision.
    groups = {}
    for row in rows:
        groups.setdefault((row["case"], row["law"], row["precision"]), {})[row["h_mm"]] = row["error_pct"]
    for row in rows:
        orders = observed_orders(groups[(row["case"], row["law"], row["precision"])])
        row["observed_order"] = orders.get(row["h_mm"])

    csv_path = args.csv or os.path.join(args.out, "crosscheck.csv")
    fields = ["case", "quantity", "h_mm", "law", "precision", "value", "fe_reference", "fe_finest",
              "fe_order", "error_pct", "observed_order", "converged", "steps", "elements", "mass_kg", "wall_s"]
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for row in rows:
            w.writerow(row)
    print(f"crosscheck: wrote {csv_path} and {fe_path}")

    status = 0
    if refused:
        status = 2
    if any(row["error_pct"] is None for row in rows):
        status = 2
    if args.bounds:
        with open(args.bounds) as f:
            bounds = json.load(f)["bounds"]
        for row in rows:
            key = f"{row['case']}/{row['h_mm']:g}/{row['law']}/{row['precision']}"
            if key not in bounds:
                print(f"crosscheck: no bound recorded for {key}", file=sys.stderr)
                status = max(status, 1)
                continue
            b = bounds[key]
            e = row["error_pct"]
            if e is None or not (b["min_pct"] <= e <= b["max_pct"]):
                print(f"crosscheck: {key}: error {e}% outside its bound [{b['min_pct']}, {b['max_pct']}]%", file=sys.stderr)
                status = max(status, 1)
            else:
                print(f"crosscheck: {key}: error {e:+.2f}% within [{b['min_pct']}, {b['max_pct']}]%")
    return status


if __name__ == "__main__":
    sys.exit(main())
