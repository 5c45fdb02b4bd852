#!/usr/bin/env bash
# Session 23, device call 4 (H200), the build of 1c9c1c5: the GPU target rows at this
# commit (36k two-term Ogden + Heun + volume, breast phantom and cube; the 1.5M linear cube),
# three rounds, --profile in the first; then the GPU tests of scripts/perf_gpu.sh's list.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
{
for r in 1 2 3; do
  p=; [ $r = 1 ] && p=--profile
  echo "== r$r 36k Ogden + volume"
  timeout 100 $G voxbreast bench --device gpu --quick --no-study --breast --sizes 33 --laws ogden --volume $p --out /tmp/a 2>&1 | grep -E "^(block|breast)|device alone"
  echo "== r$r 1.5M cube, linear"
  timeout 100 $G voxbreast bench --device gpu --quick --no-study --sizes 115 $p --out /tmp/b 2>&1 | grep -E "^(block|breast)|device alone|copy bandwidth"
done
} 2>&1 | tee $o/targets.txt
VOXBREAST_DEVICE=gpu timeout 280 $G test_physics --gtest_filter='*VolumeKernels*:VolumeConstraint.*:*KernelForces*:HyperelasticKernels.*:*BiphasicKernels*:*RestOffsets*:*TorusContact*:PersistentStep.*:Indenter.*' \
  2>&1 | grep -E '^\[ *(OK|FAILED|PASSED) *\]|tests? ran|Failure' > $o/gpu_tests.txt
tail -3 $o/gpu_tests.txt
