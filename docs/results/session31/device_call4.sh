#!/usr/bin/env bash
# Session 31, device call 4 (H200): the final commit's floor on the GPU: its test with the short
# loop's and the corrector order's, and the quick rows at 512k and 1.5M.
set -u
o=$OUT
{
VOXBREAST_DEVICE=gpu bash scripts/gpu_run.sh run test_physics --gtest_filter='GatherFloor*:UniformPath*:CorrectOrder*' 2>&1 | grep -E "^\[  (PASSED|FAILED|  OK) |FAILED|tests? ran"
bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --sizes 80 115 --out /tmp/b 2>&1 | grep -E "^block|gather floor|copy bandwidth"
} 2>&1 | tee $o/final_call4_h200.txt
