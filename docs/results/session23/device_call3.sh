#!/usr/bin/env bash
# Session 23, device call 3 (H200), the build of 1c9c1c5 (change 26): GPU tests of the step list,
# the short loop and the stepping kernels, then the full speed/accuracy study and the throughput
# series (scripts/bench_gpu.sh).
set -u
o=$OUT
VOXBREAST_DEVICE=gpu timeout 120 bash scripts/gpu_run.sh run test_physics \
  --gtest_filter='*StepList*:*UniformPath*:*UniformNeighbourhood*:*KernelSteps*:*Relaxation*:*GravityFlip*' 2>&1 \
  | grep -E "^\[ +(OK|FAILED|PASSED) |tests? ran|Failure|error" > $o/gpu_tests.txt
tail -3 $o/gpu_tests.txt
BENCH_TIMEOUT=450 bash scripts/bench_gpu.sh 2>&1 | tail -25
