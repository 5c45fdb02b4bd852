#!/usr/bin/env bash
# Session 22, device call 2 (H200): (a) the one-launch limit at 45,056 (change 25) as landed:
# cubes of 39k, 43k, 47k and the phantom resampled to 42k-46k, the default against the launched
# step (with the step list where the phantom's held share allows it), two rounds interleaved;
# (b) the GPU tests call 1 did not reach (its 300 s ran out after UniformPath).
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
run() {  # label, env..., then bench arguments after --
  local label=$1; shift; local envs=(); while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
  echo "== $label"; env "${envs[@]}" timeout 100 $G voxbreast bench --quick --no-study "$@" --out /tmp/t 2>&1 | grep -E "^(breast|block)"
  { echo "# $label"; cat /tmp/t/throughput.csv; } >> $o/one_launch_45k.csv
}
{
for r in 1 2; do
run "r$r default" X=1 -- --sizes 34 35 36 --breast-elements 42000 44000 46000
run "r$r launched" VOXBREAST_PERSISTENT=0 -- --sizes 34 35 36 --breast-elements 42000 44000 46000
run "r$r launched, list" VOXBREAST_PERSISTENT=0 VOXBREAST_STEP_LIST=1 -- --breast-elements 42000 44000 46000
done
} 2>&1 | tee $o/one_launch_45k.txt
VOXBREAST_DEVICE=gpu timeout 330 $G test_physics \
  --gtest_filter='*KernelForces*:*KernelSteps*:*StepList*:*VolumeKernels*:*RestOffsets*:*RelaxationColumn*:ReferenceState.*:*TorusContact*:*GravityFlip*' 2>&1 \
  | grep -E "^\[ +(OK|FAILED|PASSED) |tests? ran|Failure|error" > $o/gpu_tests.txt
tail -3 $o/gpu_tests.txt
