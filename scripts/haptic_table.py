#!/usr/bin/env python3
"""Markdown table of the haptic-rate rows of a bench.json (voxbreast bench --haptic), for
docs/BENCHMARKS.md ("Haptic rate").
    python3 scripts/haptic_table.py out/bench/bench.json
"""
import json
import sys


def folded(r):
    """The fold monitor's verdict; rows from before it have no such fields."""
    if "folded" not in r:
        return "—"
    return f"{'yes' if r['folded'] else 'no'} ({r['min_det_f']:.2f})"


def main(path):
    doc = json.load(open(path))
    rows = doc.get("haptic")
    if not rows:
        sys.exit(f"{path}: no 'haptic' rows (run voxbreast bench --haptic)")
    print(f"Device: {doc['device']} ({doc['platform']}), {doc['date']}, commit {doc['git_commit']}.\n")
    print("| elements | force output Hz (target 1000) | interval mean / p99 / max ms | late (> 1.5 ms) "
          "| real-time priority | deformation updates Hz | steps/update | steps/s | blew up | folded (min det F) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['elements']:,} | {r['achieved_rate_hz']:.1f} | {r['interval_mean_ms']:.3f} / "
              f"{r['interval_p99_ms']:.3f} / {r['interval_max_ms']:.3f} | {r['missed_deadlines']} "
              f"| {'yes' if r['realtime_priority'] else 'no'} | {r['update_rate_hz']:.1f} "
              f"| {r['steps_per_update']:.0f} | {r['steps_per_second']:.0f} | {'yes' if r['blown_up'] else 'no'} "
              f"| {folded(r)} |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "bench.json")
