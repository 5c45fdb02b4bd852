#!/usr/bin/env bash
# Session 21, device call 1 (H200): (a) the connection_to() refactor against its base a350945:
# PTX of the stepping program and the 1.5M cube's rate; (b) where the step list starts to pay:
# the phantom resampled from 150k to 1.5M elements, list off and on, two rounds interleaved;
# (c) GPU tests of the changed kernel code.
# Needs: .device-pkgs from `bash scripts/gpu_run.sh prepare` and .device-pkgs/base/voxbreast (a350945).
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
base=$PWD/.device-pkgs/base/voxbreast
phantom=data-samples/phantom/scene.toml
nvidia-smi --query-gpu=name,driver_version,power.limit,clocks.max.sm --format=csv,noheader > $o/device.txt
# (a) PTX: the same kernels must come out of both
for v in new base; do
  bin=voxbreast; [ $v = base ] && bin=$base
  VOXBREAST_DUMP_KERNELS=$o/ptx_$v timeout 60 $G $bin bench --quick --no-study --sizes 40 --out /tmp/ptx_$v > /dev/null 2>&1
done
( for f in $(ls $o/ptx_new); do
    if cmp -s $o/ptx_new/$f $o/ptx_base/$f; then echo "same  $f"; else echo "DIFF  $f $(diff $o/ptx_new/$f $o/ptx_base/$f | wc -l) lines"; fi
  done ) > $o/ptx_compare.txt 2>&1
cat $o/ptx_compare.txt
for r in 1 2; do
  for v in base new; do
    bin=voxbreast; [ $v = base ] && bin=$base
    echo "== round $r $v"; timeout 60 $G $bin bench --quick --no-study --sizes 115 --out /tmp/ab 2>&1 | grep -E "^block|copy bandwidth"
  done
done 2>&1 | tee $o/refactor_ab.txt
# (b) the step list against model size
sizes="150000 262144 400000 600000 900000 1200000 1500000"
for r in 1 2; do
  for L in 0 1; do
    echo "== round $r VOXBREAST_STEP_LIST=$L"
    VOXBREAST_STEP_LIST=$L timeout 120 $G voxbreast bench --quick --no-study --breast-elements $sizes --out $o/list_r${r}_$L 2>&1 | grep -E "^breast|copy bandwidth"
  done
done 2>&1 | tee $o/list_threshold.txt
for f in $o/list_r*/throughput.csv; do echo "# $f"; cat $f; done > $o/list_threshold.csv
rm -rf $o/ptx_new $o/ptx_base $o/list_r*
# (c) GPU tests of the changed connection loops
VOXBREAST_DEVICE=gpu timeout 150 $G test_physics --gtest_brief=1 \
  --gtest_filter='*KernelForces*:*KernelSteps*:*UniformPath*:*StepList*:*Relaxation*:Indenter.*:*VolumeKernels*:*RestOffsets*:*HyperelasticKernels*' 2>&1 | tail -30 | tee $o/gpu_tests.txt
