#!/usr/bin/env bash
# Session 30, device call 3 (H200): attempt 41, timing only: main's gather with the general
# connection loop compiled out (VB_TIMING_SHORT_ONLY: every free element on the short loop), to
# measure what the general loop's code costs the short loop's kernel (attempt 40 measured 6% in
# the march); quick rows at 512k, 1.5M and 4.1M against main, alternating; registers; groups.
set -u
o=$OUT
Q="bench --device gpu --quick --no-study --sizes 80 115 160"
r() { echo "== $1"; shift; env "$@" bash scripts/gpu_run.sh run voxbreast $Q --out /tmp/b 2>&1 | grep -E "^block"; }
{
for i in 1 2; do
  r main VOXBREAST_CL_OPTIONS=
  r "short loop only" VOXBREAST_CL_OPTIONS=-DVB_TIMING_SHORT_ONLY=1
done
for wg in 128 512; do
  echo "== short loop only, groups of $wg"
  VOXBREAST_STEP_WG=$wg VOXBREAST_CL_OPTIONS=-DVB_TIMING_SHORT_ONLY=1 bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --sizes 115 --out /tmp/b 2>&1 | grep -E "^block"
done
mkdir -p /tmp/dump
for opt in "" "-DVB_TIMING_SHORT_ONLY=1"; do
  rm -f /tmp/dump/*
  VOXBREAST_DUMP_KERNELS=/tmp/dump VOXBREAST_CL_OPTIONS="-cl-nv-verbose $opt" timeout 120 bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --sizes 115 --out /tmp/b >/dev/null 2>&1
  echo "== registers $opt"; grep -A4 "entry function 'heun_\(predict\|correct\)'" /tmp/dump/*.log | grep -E "entry|Used|spill"
done
} 2>&1 | tee $o/short_only_call3_h200.txt
