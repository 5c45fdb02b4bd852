#!/usr/bin/env bash
# Session 31, device call 7 (H200): after the reversed corrector's order moved into common.cl
# (shared by heun_correct and the floor): the GPU tests of the corrector order, the floor and the
# short loop, and the quick rows at 512k and 1.5M (the reversed corrector runs from 1M).
set -u
o=$OUT
{
VOXBREAST_DEVICE=gpu bash scripts/gpu_run.sh run test_physics --gtest_filter='GatherFloor*:UniformPath*:CorrectOrder*' 2>&1 | grep -E "^\[  (PASSED|FAILED|  OK) |FAILED|tests? ran"
bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --sizes 80 115 --out /tmp/b 2>&1 | grep -E "^block|gather floor|copy bandwidth"
} 2>&1 | tee $o/review_call7_h200.txt
