#!/usr/bin/env bash
# Session 39, device call 2 (H200): the kernels' frame centred on the model (Simulator::kernel_point)
# on NVIDIA's OpenCL: every test_physics suite that takes positions (contact, tori, indenters,
# the volume constraint, the one-launch step, relaxation, the reference state), test_probing
# (triangle contact) and test_force_feedback; the tightest ring at 1e-6 in float.
#   here:  cmake --build build && bash scripts/gpu_run.sh prepare
#   run:   bash docs/results/session39/device_call2.sh   (carry [".device-pkgs"])
set -u
cd "$(dirname "$0")/../../.."
G="bash scripts/gpu_run.sh run"
export VOXBREAST_DEVICE=gpu
keep() { grep -E '^\[ *(OK|FAILED|PASSED) *\]|Failure|double:|tests ran'; }
s=$(date +%s)
timeout 330 $G test_physics --gtest_brief=0 \
  --gtest_filter='*FloatRest*:*ContactBand*:*Torus*:Indenter*:Volume*:PersistentStep*:Relaxation*:ReferenceState*:GravityFlip*:Contact*' \
  2>&1 | keep >"$OUT/test_physics_h200_call2.txt"
echo "== test_physics $(( $(date +%s) - s )) s"; tail -n 2 "$OUT/test_physics_h200_call2.txt"
timeout 120 $G test_probing 2>&1 | keep >"$OUT/test_probing_h200_call2.txt"
tail -n 2 "$OUT/test_probing_h200_call2.txt"
timeout 60 $G test_force_feedback 2>&1 | keep >"$OUT/test_force_feedback_h200_call2.txt"
tail -n 2 "$OUT/test_force_feedback_h200_call2.txt"
timeout 60 $G voxbreast simulate docs/results/session39/ring050.toml --out "$OUT/ring_float" --precision float \
  --device gpu >"$OUT/ring050_heun_1e-6_float_h200_call2.log" 2>&1
grep -E 'equilibrium|max_steps' "$OUT/ring050_heun_1e-6_float_h200_call2.log"
rm -rf "$OUT/ring_float"
