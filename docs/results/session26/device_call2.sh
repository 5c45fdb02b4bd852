#!/usr/bin/env bash
# Session 26, device call 2 (H200): the rest of test_physics on NVIDIA's OpenCL (call 1 ran the
# suites up to the relaxation tests in 420 s, PersistentStep.* 170 s of them): from the relaxation
# suites on, and every parameterised suite.
set -u
o=$OUT
export VOXBREAST_DEVICE=gpu
s=$(date +%s)
timeout 560 bash scripts/gpu_run.sh run test_physics --gtest_brief=1 \
  --gtest_filter='Relaxation*:UniformNeighbourhood.*:UniformPath.*:StepList.*:StepWorkGroup.*:ReferenceState.*:Torus*:GravityFlip.*:*/*' \
  > $o/test_physics_rest.txt 2>&1
echo "== test_physics (rest) rc=$? $(( $(date +%s) - s )) s"
grep -E "^\[  (PASSED|FAILED) |^\[  FAILED|tests ran" $o/test_physics_rest.txt | head -20
