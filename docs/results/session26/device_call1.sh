#!/usr/bin/env bash
# Session 26, device call 1 (H200): every test of the four test binaries that run OpenCL
# (test_physics, test_probing, test_fit, test_force_feedback) on NVIDIA's OpenCL, unfiltered:
# earlier calls ran filtered subsets, and a whole run once found a GPU-only bug (BENCHMARKS.md,
# set_gravity and the one-launch step).
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
export VOXBREAST_DEVICE=gpu
for t in test_probing test_fit test_force_feedback test_physics; do
  s=$(date +%s)
  timeout 420 $G $t --gtest_brief=1 > $o/$t.txt 2>&1
  echo "== $t rc=$? $(( $(date +%s) - s )) s"
  grep -E "^\[  (PASSED|FAILED) |^\[  FAILED|tests ran" $o/$t.txt | head -20
done
