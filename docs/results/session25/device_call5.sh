#!/usr/bin/env bash
# Session 25, device call 5 (H200): (a) the prototype's stage pair (layout 5) timed in rounds of
# 2,000 and 10,000 steps, with the SM clock and power logged every 100 ms: is its timed rate,
# 12% above main's device-alone figure, a power-cap effect? (b) main's 1.5M step with work-groups
# of 64, 128 (as landed) and 256 (VOXBREAST_STEP_WG, an experiment not kept).
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
P=docs/results/session25/proto_walk.cl
nvidia-smi --query-gpu=timestamp,clocks.sm,power.draw,clocks_throttle_reasons.active --format=csv -lms 100 > $o/clocks_call5_h200.csv &
smi=$!
{
for s in 2000 10000; do
  echo "== prototype, rounds of $s steps, $(date +%T.%N)"
  timeout 120 $G .device-pkgs/proto_walk 115 $s $P "5 5" "1" 128 "0" | grep steps
done
for r in 1 2; do for w in 128 256 64; do
  echo "== r$r main, work-group $w, $(date +%T.%N)"
  VOXBREAST_STEP_WG=$w timeout 100 $G voxbreast bench --quick --no-study --sizes 115 80 --out /tmp/t 2>&1 | grep -E "device alone|steps/s"
done; done
} 2>&1 | tee $o/wg_power_h200.txt
kill $smi
