#!/usr/bin/env bash
# Session 26, device call 7 (H200): change 29 (Heun's corrector into a second pair of state arrays,
# VB_PING_PONG): its tests and the neighbouring ones on the GPU, then the quick cube rows with the
# rule (the pair from 131,072 elements) against VOXBREAST_PING_PONG=0, two rounds interleaved.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
VOXBREAST_DEVICE=gpu timeout 150 $G test_physics --gtest_brief=1 --gtest_filter='PingPong.*:StepWorkGroup.*:StepList.*:UniformPath.*:Integrators/KernelSteps.*' 2>&1 | tail -8 | tee $o/gpu_tests_call7_h200.txt
{
for r in 1 2; do for v in rule 0; do
  echo "== r$r $v"
  if [ $v = rule ]; then unset VOXBREAST_PING_PONG; else export VOXBREAST_PING_PONG=0; fi
  timeout 150 $G voxbreast bench --device gpu --quick --no-study --sizes 40 50 64 80 115 160 --out $o/b_${v}_$r 2>&1 | grep -E "steps/s"
done; done
unset VOXBREAST_PING_PONG
} 2>&1 | tee $o/ping_pong_h200.txt
