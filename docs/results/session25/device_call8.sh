#!/usr/bin/env bash
# Session 25, device call 8 (H200): the step's work-group size 128 against 256 (VOXBREAST_STEP_WG,
# now also over the step list) with the list (the 1.5M and 500k phantoms) and the other
# integrators (symplectic Euler, relaxation) on cubes.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
{
for r in 1 2; do for w in 128 256; do
  echo "== r$r work-group $w"
  VOXBREAST_STEP_WG=$w timeout 140 $G voxbreast bench --quick --no-study --sizes 64 115 --integrators heun symplectic_euler relaxation \
     --breast-large --breast-elements 500000 --out /tmp/t$w 2>&1 | grep -E "steps/s"
done; done
} 2>&1 | tee $o/wg_list_h200.txt
