#!/usr/bin/env bash
# Session 25, device call 6 (H200): the step's work-group size (VOXBREAST_STEP_WG, experiment)
# over the cube series and the quick bench's other rows (phantom, Ogden, the 36k target row).
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
{
for r in 1 2; do for w in 128 256 512 1024; do
  echo "== r$r cubes, work-group $w"
  VOXBREAST_STEP_WG=$w timeout 100 $G voxbreast bench --quick --no-study --sizes 40 64 80 115 160 --out /tmp/t 2>&1 | grep -E "steps/s"
done; done
for w in 128 256; do
  echo "== quick bench, work-group $w"
  VOXBREAST_STEP_WG=$w timeout 150 $G voxbreast bench --quick --no-study --out $o/quick_wg$w 2>&1 | grep -E "steps/s"
done
} 2>&1 | tee $o/wg_series_h200.txt
