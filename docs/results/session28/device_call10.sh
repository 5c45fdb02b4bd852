#!/usr/bin/env bash
# Session 28, device call 10 (H200): the GPU tests after change 30 (the short loop's connection
# as s·r): test_fit, test_force_feedback, test_probing unfiltered, test_physics but for the
# one-launch step's suite (PersistentStep.*, which has no short loop; call 9 ran UniformPath.*,
# UniformNeighbourhood.*, CorrectOrder.* and StepWorkGroup.*).
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
export VOXBREAST_DEVICE=gpu
for t in test_fit test_force_feedback test_probing; do
  s=$(date +%s)
  timeout 120 $G $t --gtest_brief=1 > $o/$t.txt 2>&1
  echo "== $t rc=$? $(( $(date +%s) - s )) s"
  grep -E "^\[  (PASSED|FAILED) |^\[  FAILED|tests ran|SKIPPED" $o/$t.txt | head -10
done
s=$(date +%s)
timeout 330 $G test_physics --gtest_brief=1 --gtest_filter='-PersistentStep.*:UniformPath.*:UniformNeighbourhood.*:CorrectOrder.*:StepWorkGroup.*' > $o/test_physics.txt 2>&1
echo "== test_physics rc=$? $(( $(date +%s) - s )) s"
grep -E "^\[  (PASSED|FAILED) |^\[  FAILED|tests ran|SKIPPED" $o/test_physics.txt | head -20
