#!/usr/bin/env bash
# Session 21, device call 4 (H200), the landed rules (one-launch step ≤ 40,960 elements, step list
# above 65,536): GPU tests, then the throughput series 10k-9.9M (cubes) and the phantom resampled
# from 36k to 1.5M.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
VOXBREAST_DEVICE=gpu timeout 200 $G test_physics \
  --gtest_filter='*KernelForces*:*KernelSteps*:*UniformPath*:*StepList*:*Relaxation*:Indenter.*:*VolumeKernels*:*HyperelasticKernels*:PersistentStep.*:GravityFlip.*:TorusContact.*:TorusFriction.*:*SphereAnchorPose*:ReferenceState.*' 2>&1 \
  | grep -E "^\[ +(OK|FAILED|PASSED|SKIPPED) |tests? ran|Failure|error" > $o/gpu_tests.txt
tail -4 $o/gpu_tests.txt; grep -c "OK \]" $o/gpu_tests.txt
mkdir -p $o/bench
timeout 370 $G voxbreast bench --device gpu --no-study --sizes 22 33 40 50 64 80 115 160 215 --breast-large \
  --breast-elements 36000 75000 150000 270000 600000 --phantom data-samples/phantom/scene.toml --out $o/bench 2>&1 \
  | grep -E "^(breast|block)|copy bandwidth" | tee $o/bench/bench.log
