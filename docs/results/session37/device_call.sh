#!/usr/bin/env bash
# Session 37, one device call (H200): the push contact's landing rule (e6e68a4) on NVIDIA's
# OpenCL: the GPU tests of contact (tori, indenters, the band), relaxation, probing and the haptic
# probe, then the positioning samples (the device sample, the device-design sweep, now by
# relaxation, and the phantom sweep). Text results only.
#   here:  cmake --build build && bash scripts/gpu_run.sh prepare
#   run:   bash docs/results/session37/device_call.sh   (carry [".device-pkgs"])
set -uo pipefail
cd "$(dirname "$0")/../../.."
keep() { grep -E '^\[ *(OK|FAILED|PASSED) *\]|Failure|bottom element|ring force|plate |slide|mean height'; }
timeout 120 bash scripts/gpu_run.sh run test_physics --gtest_filter='*ContactBand*:*Torus*:Indenter.*:Relaxation*' 2>&1 |
  keep >"$OUT/test_physics_h200.txt"
tail -n 2 "$OUT/test_physics_h200.txt"
timeout 200 bash scripts/gpu_run.sh run test_probing 2>&1 | keep >"$OUT/test_probing_h200.txt"
tail -n 2 "$OUT/test_probing_h200.txt"
timeout 100 bash scripts/gpu_run.sh run test_force_feedback 2>&1 | keep >"$OUT/test_force_feedback_h200.txt"
tail -n 2 "$OUT/test_force_feedback_h200.txt"
timeout 150 bash scripts/gpu_positioning.sh
