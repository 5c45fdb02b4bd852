#!/usr/bin/env bash
# Session 35's second device call: the unloaded reference state's fit (fit.unloaded_reference,
# [reference_state] ct_posture = "supine" instead of from_posture) with its two simulators kept
# (commit after 4937d8a) against the reference b556f39, interleaved, on gpu_fit.sh's phantom;
# first the GPU test of those solves (test_fit ForwardModel*). Text results only.
set -uo pipefail
cd "$(dirname "$0")/../../.."
ref=$(mktemp -d) && tar -C "$ref" -xJf .device-pkgs/ref.tar.xz
VOXBREAST_DEVICE=gpu timeout 120 bash scripts/gpu_run.sh run test_fit --gtest_filter='*ForwardModel*' 2>&1 |
  grep -E '^\[ *(OK|FAILED|PASSED) *\]|Failure' >"$OUT/test_fit.txt"
OUT=$(mktemp -d) MAX_ITERATIONS=1 timeout 120 bash scripts/gpu_fit.sh >/dev/null 2>&1  # builds the phantom and its observation
ph=$(ls -d /tmp/tmp.*/fit/ph | head -1)
sed -e 's/^from_posture = "supine"$//' -e 's/^max_iterations = .*/max_iterations = 10/' \
    -e 's/^\[fit\]$/[reference_state]\nct_posture = "supine"\n[fit]/' "$ph/fit_sequential.toml" >"$ph/fit_reference.toml"
for round in 1 2; do
  for b in new ref; do
    bin=voxbreast; [[ $b == ref ]] && bin=$ref/bin/voxbreast
    o=$(mktemp -d)
    { echo "== ${b}_r$round"; ( cd "$ph" && time bash "$OLDPWD/scripts/gpu_run.sh" run "$bin" fit fit_reference.toml --device gpu --out "$o" --no-plots ); } >>"$OUT/reference_fit.txt" 2>&1
    grep -h '"wall_time_s"\|"jacobian_wall_time_s"\|"reference_state_solves"\|"forward_solves"' "$o/summary.json" >>"$OUT/reference_fit.txt"
  done
done
cat "$OUT/reference_fit.txt" | grep -E '^== |fit:|real|_s"|solves"'
