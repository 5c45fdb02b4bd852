#!/usr/bin/env bash
# Session 25, device call 7 (H200): the step's work-group size 128 against 256
# (VOXBREAST_STEP_WG) on the other rows the step kernels serve with one work-item per element and
# no step list: hyperelastic cubes, the volume constraint, the resampled phantom, double.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
{
for r in 1; do for w in 128 256; do
  echo "== r$r work-group $w"
  VOXBREAST_STEP_WG=$w timeout 270 $G voxbreast bench --quick --no-study --sizes 64 115 --laws linear neo-hookean ogden --volume \
     --breast --breast-elements 120000 500000 --out /tmp/t$w 2>&1 | grep -E "steps/s|device alone"
done; done
} 2>&1 | tee $o/wg_laws_h200.txt
