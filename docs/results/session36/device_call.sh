#!/usr/bin/env bash
# Session 36, one device call (H200): the fit's timing with relaxation's bounds from one walk
# (bcc0293, bdd3455), two rounds, the unloaded reference state's fit with its jacobian_timing per
# phase, and the GPU tests of the kept simulator and relaxation. Text results only.
#   here:  cmake --build build && bash scripts/gpu_run.sh prepare
#   run:   bash docs/results/session36/device_call.sh   (carry [".device-pkgs"])
set -uo pipefail
cd "$(dirname "$0")/../../.."
work=$(mktemp -d)
for round in 1 2; do
  OUT=$work/round$round timeout 150 bash scripts/gpu_fit.sh >"$work/fit_round$round.log" 2>&1
  cp "$work/round$round/fit/timing.txt" "$OUT/fit_timing_round${round}_h200.txt"
  grep -E '^== |real|jacobian_timing|wall_time' "$OUT/fit_timing_round${round}_h200.txt"
done
# the unloaded reference state's fit (as session 35's device_call2.sh)
ph=$work/round1/fit/ph
sed -e 's/^from_posture = "supine"$//' -e 's/^\[fit\]$/[reference_state]\nct_posture = "supine"\n[fit]/' \
    "$ph/fit_sequential.toml" >"$ph/fit_reference.toml"
( cd "$ph" && time timeout 120 bash "$OLDPWD/scripts/gpu_run.sh" run voxbreast fit fit_reference.toml --device gpu \
    --out "$work/reference" --no-plots ) >"$OUT/reference_fit_h200.txt" 2>&1
python3 -c "import json,sys; s=json.load(open(sys.argv[1])); t=s['jacobian_timing']; print('reference fit: wall', s.get('wall_time_s'), 'jacobians', s.get('jacobian_wall_time_s'), ', '.join(f'{k} {v:.4g}' for k, v in t.items()))" \
  "$work/reference/summary.json" | tee -a "$OUT/reference_fit_h200.txt"
grep real "$OUT/reference_fit_h200.txt"
timeout 150 bash scripts/gpu_run.sh run test_physics --gtest_filter='*SetMaterials*:Relaxation*' 2>&1 |
  grep -E '^\[ *(OK|FAILED|PASSED) *\]|Failure' >"$OUT/test_physics_h200.txt"
tail -n 3 "$OUT/test_physics_h200.txt"
