#!/usr/bin/env bash
# Session 26, device call 9 (H200): change 29 (Heun's corrector over the elements' blocks from the
# last to the first, VB_CORRECT_REVERSE): its tests and the short loop's on the GPU, then the quick
# cube rows with the rule (from 131,072 elements) against VOXBREAST_CORRECT_REVERSE=0, two rounds
# interleaved.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
VOXBREAST_DEVICE=gpu timeout 120 $G test_physics --gtest_brief=1 --gtest_filter='CorrectOrder.*:UniformPath.*' 2>&1 | tail -4 | tee $o/gpu_tests_call9_h200.txt
{
for r in 1 2; do for v in rule 0; do
  echo "== r$r $v"
  if [ $v = rule ]; then unset VOXBREAST_CORRECT_REVERSE; else export VOXBREAST_CORRECT_REVERSE=0; fi
  timeout 150 $G voxbreast bench --device gpu --quick --no-study --sizes 40 50 64 80 115 160 --out $o/b_${v}_$r 2>&1 | grep -E "steps/s"
done; done
unset VOXBREAST_CORRECT_REVERSE
} 2>&1 | tee $o/correct_reverse_h200.txt
