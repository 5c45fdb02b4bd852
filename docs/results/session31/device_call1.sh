#!/usr/bin/env bash
# Session 31, device call 1 (H200): the gather floor (engine/bench/gather_floor.hpp) beside the
# step: its GPU test, the quick throughput rows from 125k to 4.1M twice, and the registers of the
# floor's kernels and the step's at 1.5M.
set -u
o=$OUT
Q="bench --device gpu --quick --no-study --sizes 50 80 115 160"
{
echo "== GPU tests"
VOXBREAST_DEVICE=gpu bash scripts/gpu_run.sh run test_physics --gtest_filter='GatherFloor*:UniformPath*:CorrectOrder*' 2>&1 | grep -E "^\[  (PASSED|FAILED|  OK) |FAILED|tests? ran"
for i in 1 2; do
  echo "== round $i"
  bash scripts/gpu_run.sh run voxbreast $Q --out /tmp/b$i 2>&1 | grep -E "^block|gather floor|copy bandwidth"
done
cp /tmp/b1/throughput.csv $o/floor_round1_h200.csv; cp /tmp/b2/throughput.csv $o/floor_round2_h200.csv
mkdir -p /tmp/dump
VOXBREAST_DUMP_KERNELS=/tmp/dump VOXBREAST_CL_OPTIONS="-cl-nv-verbose" timeout 120 bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --sizes 115 --out /tmp/b >/dev/null 2>&1
echo "== registers"; grep -A4 "entry function '\(heun_\(predict\|correct\)\|gather_floor_\(predict\|correct\)\)'" /tmp/dump/*.log | grep -E "entry|Used|spill"
} 2>&1 | tee $o/floor_call1_h200.txt
