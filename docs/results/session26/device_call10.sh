#!/usr/bin/env bash
# Session 26, device call 10 (H200): change 29 between and beyond call 9's sizes: the 1.0M and 1.5M
# cubes, linear and two-term Ogden, with and without the volume constraint, the corrector's blocks
# reversed (VOXBREAST_CORRECT_REVERSE=1) against forward (=0).
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
{
for v in 1 0; do
  echo "== reverse $v"
  VOXBREAST_CORRECT_REVERSE=$v timeout 110 $G voxbreast bench --device gpu --quick --no-study --sizes 100 115 --laws linear ogden --volume --out $o/r$v 2>&1 | grep -E "steps/s"
done
} 2>&1 | tee $o/correct_reverse_laws_h200.txt
