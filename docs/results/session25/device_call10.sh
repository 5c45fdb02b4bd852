#!/usr/bin/env bash
# Session 25, device call 10 (H200): change 28 as committed (the stepping kernels in groups of 256
# from 131,072 elements): its tests and the neighbouring ones on the GPU, and the quick throughput
# rows with the rule against VOXBREAST_STEP_WG=128, two rounds.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
VOXBREAST_DEVICE=gpu timeout 200 $G test_physics --gtest_filter='StepWorkGroup.*:StepList.*:UniformPath.*:PersistentStep.*' 2>&1 | tail -30 | tee $o/gpu_tests_call10_h200.txt
{
for r in 1 2; do for v in rule 128; do
  echo "== r$r $v"
  if [ $v = rule ]; then unset VOXBREAST_STEP_WG; else export VOXBREAST_STEP_WG=128; fi
  timeout 120 $G voxbreast bench --quick --no-study --sizes 40 64 80 115 --breast-large --out $o/b_${v}_$r 2>&1 | grep -E "steps/s"
done; done
unset VOXBREAST_STEP_WG
} 2>&1 | tee $o/rule_h200.txt
