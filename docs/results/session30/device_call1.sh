#!/usr/bin/env bash
# Session 30, device call 1 (H200): change 31, Heun's stages marching up column pieces
# (kernels/march.cl), against the gather (VOXBREAST_MARCH=0) in alternating quick rows from 262k
# to 4.1M; the march's registers and spills; its GPU tests and the short loop's.
set -u
o=$OUT
Q="bench --device gpu --quick --no-study --sizes 51 64 80 115 160"
{
for i in 1 2; do
  echo "== gather"; VOXBREAST_MARCH=0 bash scripts/gpu_run.sh run voxbreast $Q --out /tmp/bg 2>&1 | grep -E "^block"
  echo "== march"; bash scripts/gpu_run.sh run voxbreast $Q --out /tmp/bm 2>&1 | grep -E "^block"
done
for wg in 64 256; do
  echo "== march, groups of $wg"; VOXBREAST_STEP_WG=$wg bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --sizes 115 --out /tmp/bw 2>&1 | grep -E "^block"
done
mkdir -p /tmp/dump
VOXBREAST_DUMP_KERNELS=/tmp/dump VOXBREAST_CL_OPTIONS=-cl-nv-verbose timeout 120 bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --sizes 115 --out /tmp/b 2>&1 | grep -E "^block"
grep -A4 "entry function 'heun_" /tmp/dump/*.log | grep -E "entry|Used|spill"
VOXBREAST_DEVICE=gpu timeout 240 bash scripts/gpu_run.sh run test_physics --gtest_brief=1 --gtest_filter='March*:UniformPath*:UniformNeighbourhood*:CorrectOrder*' 2>&1 | grep -v "warnings generated" | tail -14
} 2>&1 | tee $o/march_call1_h200.txt
