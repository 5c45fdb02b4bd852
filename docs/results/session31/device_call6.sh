#!/usr/bin/env bash
# Session 31, device call 6 (H200): the floor's test with and without dashpots, and the quick
# rows from 512k to 4.1M with the cube's dashpots (ζ = 0.1) and without (--dashpot-ratio 0),
# alternating, twice: what the dashpots cost the step and its floor.
set -u
o=$OUT
Q="bench --device gpu --quick --no-study --sizes 80 115 160"
{
VOXBREAST_DEVICE=gpu bash scripts/gpu_run.sh run test_physics --gtest_filter='GatherFloor*:UniformPath*:CorrectOrder*' 2>&1 | grep -E "^\[  (PASSED|FAILED|  OK) |FAILED|tests? ran"
for i in 1 2; do
  for z in 0.1 0; do
    echo "== round $i, dashpot ratio $z"
    bash scripts/gpu_run.sh run voxbreast $Q --dashpot-ratio $z --out /tmp/b_${i}_$z 2>&1 | grep -E "^block|gather floor|copy bandwidth"
    cp /tmp/b_${i}_$z/throughput.csv $o/dashpots_${z}_round${i}_h200.csv
  done
done
} 2>&1 | tee $o/dashpots_call6_h200.txt
