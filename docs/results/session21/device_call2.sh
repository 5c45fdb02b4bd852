#!/usr/bin/env bash
# Session 21, device call 2 (H200): (a) connection_to() with out-parameters against a350945 (PTX,
# the 1.5M cube); (b) the one-launch step against the launched step with and without the step
# list, phantom resampled to 36k-220k (Heun); (c) the list for relaxation and symplectic Euler,
# 18k-600k; (d) cubes of 125k and 216k, one-launch or not; (e) GPU tests of the changed loops.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
base=$PWD/.device-pkgs/base/voxbreast
for v in new base; do
  bin=voxbreast; [ $v = base ] && bin=$base
  VOXBREAST_DUMP_KERNELS=/tmp/ptx_$v timeout 60 $G $bin bench --quick --no-study --sizes 40 --out /tmp/ptx_$v > /dev/null 2>&1
done
for f in $(ls /tmp/ptx_new); do
  if cmp -s /tmp/ptx_new/$f /tmp/ptx_base/$f; then echo "same  $f"; else echo "DIFF  $f $(diff /tmp/ptx_new/$f /tmp/ptx_base/$f | wc -l) lines"; fi
done 2>&1 | tee $o/ptx_compare.txt
for r in 1 2; do
  for v in base new; do
    bin=voxbreast; [ $v = base ] && bin=$base
    echo "== round $r $v"; timeout 60 $G $bin bench --quick --no-study --sizes 115 --out /tmp/ab 2>&1 | grep -E "^block|copy bandwidth"
  done
done 2>&1 | tee $o/refactor_ab.txt
run() {  # label, env..., then bench arguments after --
  local label=$1; shift; local envs=(); while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
  echo "== $label"; env "${envs[@]}" timeout 120 $G voxbreast bench --quick --no-study "$@" --out /tmp/t 2>&1 | grep -E "^(breast|block)"
  { echo "# $label"; cat /tmp/t/throughput.csv; } >> $o/study.csv
}
{
mid="36000 75000 150000 220000"
run "heun default (one-launch)" X=1 -- --breast-elements $mid
run "heun launched, no list" VOXBREAST_PERSISTENT=0 -- --breast-elements $mid
run "heun launched, list" VOXBREAST_PERSISTENT=0 VOXBREAST_STEP_LIST=1 -- --breast-elements $mid
sizes="18000 36000 75000 150000 270000 600000"
run "relaxation+euler, no list" VOXBREAST_STEP_LIST=0 -- --breast-elements $sizes --integrators relaxation symplectic_euler
run "relaxation+euler, list" VOXBREAST_STEP_LIST=1 -- --breast-elements $sizes --integrators relaxation symplectic_euler
run "cubes default" X=1 -- --sizes 33 50 60
run "cubes launched" VOXBREAST_PERSISTENT=0 -- --sizes 33 50 60
} 2>&1 | tee $o/study.txt
VOXBREAST_DEVICE=gpu timeout 240 $G test_physics \
  --gtest_filter='*KernelForces*:*KernelSteps*:*UniformPath*:*StepList*:*Relaxation*:Indenter.*:*VolumeKernels*:*RestOffsets*:*HyperelasticKernels*' 2>&1 \
  | grep -E "^\[ +(OK|FAILED|PASSED) |tests? ran|Failure|error" | tail -60 > $o/gpu_tests.txt
tail -5 $o/gpu_tests.txt
