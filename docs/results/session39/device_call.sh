#!/usr/bin/env bash
# Session 39, one device call (H200): push contact taking distances within the precision's
# resolution as zero, on NVIDIA's OpenCL: the GPU tests of contact (FloatRest, ContactBand, tori,
# indenters, relaxation), probing and the haptic probe; the tightest ring at 1e-6 in float and
# double; then the positioning samples (scripts/gpu_positioning.sh). Text results only.
#   here:  cmake --build build && bash scripts/gpu_run.sh prepare
#   run:   bash docs/results/session39/device_call.sh   (carry [".device-pkgs"])
set -uo pipefail
cd "$(dirname "$0")/../../.."
keep() { grep -E '^\[ *(OK|FAILED|PASSED) *\]|Failure|bottom element|double:|ring force|plate |slide|mean height'; }
timeout 150 bash scripts/gpu_run.sh run test_physics \
  --gtest_filter='*FloatRest*:*ContactBand*:*Torus*:Indenter.*:Relaxation*:FloatFloorHint*' 2>&1 |
  keep >"$OUT/test_physics_h200.txt"
tail -n 2 "$OUT/test_physics_h200.txt"
timeout 200 bash scripts/gpu_run.sh run test_probing 2>&1 | keep >"$OUT/test_probing_h200.txt"
tail -n 2 "$OUT/test_probing_h200.txt"
timeout 100 bash scripts/gpu_run.sh run test_force_feedback 2>&1 | keep >"$OUT/test_force_feedback_h200.txt"
tail -n 2 "$OUT/test_force_feedback_h200.txt"
for p in float double; do
  timeout 120 bash scripts/gpu_run.sh run voxbreast simulate docs/results/session39/ring050.toml \
    --out "$OUT/ring_$p" --precision "$p" --device gpu --quiet >"$OUT/ring_$p.log" 2>&1
  rm -f "$OUT/ring_$p/result.h5"
  tail -n 3 "$OUT/ring_$p.log"
done
timeout 150 bash scripts/gpu_positioning.sh
