#!/usr/bin/env bash
# Session 21, device call 7 (H200): Heun's split force pass for hyperelastic models (2 work-items
# per element on GPUs up to 262,144 elements) against one work-item per element (with the step
# list where the phantom's held share allows it): Ogden cubes of 36k-262k and the phantom resampled.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
for r in 1 2; do
  for S in 2 1; do
    echo "== round $r VOXBREAST_FORCE_SPLIT=$S"
    VOXBREAST_FORCE_SPLIT=$S timeout 100 $G voxbreast bench --quick --no-study --sizes 33 50 64 --laws ogden \
      --breast-elements 36000 75000 150000 250000 --out /tmp/s 2>&1 | grep -E "^(block|breast).*ogden"
  done
done 2>&1 | tee $o/split_ogden_h200.txt
