#!/usr/bin/env bash
# Session 22, device call 1 (H200): (a) GPU tests of 3c8767d, the build with all three launch
# rules of change 24 (the split limit 98,304 had no GPU test run after it); (b) the launch rules'
# limits between the points session 21 measured: the one-launch step at 39k and 43k (limit
# 40,960), the split force pass at 80k-104k (limit 98,304), the step list at 55k-65k (limit
# 65,536); each rule forced on and off, two rounds interleaved.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
nvidia-smi --query-gpu=name,driver_version,power.limit,clocks.max.sm --format=csv,noheader > $o/device.txt
VOXBREAST_DEVICE=gpu timeout 300 $G test_physics \
  --gtest_filter='*KernelForces*:*KernelSteps*:*UniformPath*:*StepList*:*Relaxation*:Indenter.*:*VolumeKernels*:*RestOffsets*:*HyperelasticKernels*:*PersistentStep*:*TorusContact*:*GravityFlip*' 2>&1 \
  | grep -E "^\[ +(OK|FAILED|PASSED) |tests? ran|Failure|error" > $o/gpu_tests.txt
tail -3 $o/gpu_tests.txt
run() {  # label, env..., then bench arguments after --
  local label=$1; shift; local envs=(); while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
  echo "== $label"; env "${envs[@]}" timeout 100 $G voxbreast bench --quick --no-study "$@" --out /tmp/t 2>&1 | grep -E "^(breast|block)"
  { echo "# $label"; cat /tmp/t/throughput.csv; } >> $o/limits.csv
}
{
for r in 1 2; do
run "r$r one-launch on" VOXBREAST_PERSISTENT=1 -- --sizes 34 35
run "r$r one-launch off" VOXBREAST_PERSISTENT=0 -- --sizes 34 35
run "r$r split on" VOXBREAST_FORCE_SPLIT=2 -- --sizes 43 45 47 --laws ogden --breast-elements 90000 110000
run "r$r split off" VOXBREAST_FORCE_SPLIT=1 -- --sizes 43 45 47 --laws ogden --breast-elements 90000 110000
run "r$r list on" VOXBREAST_STEP_LIST=1 -- --breast-elements 55000 65000 --laws linear ogden
run "r$r list off" VOXBREAST_STEP_LIST=0 -- --breast-elements 55000 65000 --laws linear ogden
done
} 2>&1 | tee $o/limits.txt
