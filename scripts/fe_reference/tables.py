#!/usr/bin/env python3
"""Markdown tables of the FE cross-check for docs/VALIDATION.md.

  python3 scripts/fe_reference/tables.py --fe fe_reference.json [LABEL=crosscheck.csv ...]

Prints the FE convergence study (answer per mesh level, limit, observed order) and, per CSV,
VoxBreast's error per case, spacing, law and precision with the observed order in h.
"""
import argparse
import csv
import json


def fmt(x, spec="{:.4f}"):
    return "—" if x is None or x == "" else spec.format(float(x))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--fe", required=True)
    ap.add_argument("inputs", nargs="*", help="LABEL=CSV")
    args = ap.parse_args()
    with open(args.fe) as f:
        fe = json.load(f)

    print("| case (body) | quantity | FE levels: answer (unknowns) | limit | observed order | converged |")
    print("|---|---|---|---|---|---|")
    for key, s in fe.items():
        levels = "; ".join(f"{l['level']}: {fmt(l['value'], '{:.5g}')} ({l['dofs']})" for l in s["levels"])
        extra = f" (closed form {s['closed_form']:.5g})" if "closed_form" in s else ""
        print(f"| {key} | {s['quantity']} | {levels} | {fmt(s.get('limit'), '{:.5g}')}{extra} | "
              f"{fmt(s.get('order'), '{:.2f}')} | {'yes' if s['converged'] else '**no**'} |")

    for spec in args.inputs:
        label, path = spec.split("=", 1)
        with open(path) as f:
            rows = list(csv.DictReader(f))
        print(f"\n**{label}**\n")
        print("| case | law | precision | h = 4 mm | h = 2 mm | h = 1 mm | observed order (4→2, 2→1) |")
        print("|---|---|---|---|---|---|---|")
        groups = {}
        for r in rows:
            groups.setdefault((r["case"], r["law"], r["precision"]), {})[float(r["h_mm"])] = r
        for (case, law, prec), by_h in groups.items():
            cells = []
            for h in (4.0, 2.0, 1.0):
                r = by_h.get(h)
                if r is None:
                    cells.append("not run")
                elif not r["error_pct"]:
                    cells.append("did not converge")
                else:
                    cells.append(f"{float(r['error_pct']):+.2f}%")
            orders = ", ".join(fmt(by_h[h]["observed_order"], "{:.2f}") if h in by_h else "—" for h in (2.0, 1.0))
            print(f"| {case} | {law} | {prec} | {' | '.join(cells)} | {orders} |")


if __name__ == "__main__":
    main()
