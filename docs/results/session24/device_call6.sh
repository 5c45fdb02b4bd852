#!/usr/bin/env bash
# Session 24, device call 6 (H200): change 27 as committed (the default rule: packed where the short
# loop takes half the free elements). GPU tests; then the cubes and the phantom at 60k by default
# and with VOXBREAST_PRED_PACKED=0, two rounds interleaved; the 36k target row for the record.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
VOXBREAST_DEVICE=gpu timeout 300 $G test_physics \
  --gtest_filter='*UniformPath*:*UniformNeighbourhood*:*KernelForces*:*KernelSteps*:*StepList*:*GravityFlip*:*Persistent*:*VolumeKernels*' 2>&1 \
  | grep -E "^\[ +(OK|FAILED|PASSED) |tests? ran|Failure|error|short vs" > $o/gpu_tests.txt
tail -3 $o/gpu_tests.txt
run() {  # label, env..., then bench arguments after --
  local label=$1; shift; local envs=(); while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
  echo "== $label"; env "${envs[@]}" timeout 150 $G voxbreast bench --quick --no-study "$@" --out /tmp/t 2>&1 | grep -E "^(breast|block)|device alone|copy"
  { echo "# $label"; cat /tmp/t/throughput.csv; } >> $o/rule.csv
  cp /tmp/t/bench.json "$o/rule_${label// /_}.json" 2>/dev/null
}
{
for r in 1 2; do
  run "r$r default" X=1 -- --sizes 64 80 115 --breast-elements 60000 --profile
  run "r$r off" VOXBREAST_PRED_PACKED=0 -- --sizes 64 80 115 --breast-elements 60000 --profile
done
run "target" X=1 -- --breast --laws ogden --volume
} 2>&1 | tee $o/rule.txt
