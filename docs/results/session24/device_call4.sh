#!/usr/bin/env bash
# Session 24, device call 4 (H200): change 27, Heun's predicted stage packed (VB_PRED_PACKED).
# GPU tests of the short loop, the kernels and the step list; then cubes of 64k, 262k, 512k and
# 1.5M elements and the phantom resampled to 50k and 60k (the short loop's sizes without the list),
# linear + Heun float, packed off and on, three rounds interleaved, --profile in the first.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
nvidia-smi --query-gpu=name,driver_version,power.limit,clocks.max.sm --format=csv,noheader > $o/device.txt
VOXBREAST_DEVICE=gpu timeout 240 $G test_physics \
  --gtest_filter='*UniformPath*:*UniformNeighbourhood*:*KernelForces*:*KernelSteps*:*StepList*:*GravityFlip*' 2>&1 \
  | grep -E "^\[ +(OK|FAILED|PASSED) |tests? ran|Failure|error|short vs" > $o/gpu_tests.txt
tail -3 $o/gpu_tests.txt
run() {  # label, env..., then bench arguments after --
  local label=$1; shift; local envs=(); while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
  echo "== $label"; env "${envs[@]}" timeout 150 $G voxbreast bench --quick --no-study "$@" --out /tmp/t 2>&1 | grep -E "^(breast|block)|device|host|copy"
  { echo "# $label"; cat /tmp/t/throughput.csv; } >> $o/packed.csv
  cp /tmp/t/throughput.json $o/packed_${label// /_}.json 2>/dev/null
}
{
for r in 1 2 3; do
  p=; [ $r = 1 ] && p=--profile
  run "r$r off" VOXBREAST_PRED_PACKED=0 -- --sizes 40 64 80 115 --breast-elements 50000 60000 $p
  run "r$r on" X=1 -- --sizes 40 64 80 115 --breast-elements 50000 60000 $p
done
} 2>&1 | tee $o/packed.txt
