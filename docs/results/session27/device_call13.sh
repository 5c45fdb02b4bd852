#!/usr/bin/env bash
# Session 27, device call 13 (H200): main's step at 1.5M under register caps. Session 26 read main's
# heun_predict / heun_correct at 61 / 62 registers (4 groups of 256 per SM, 32 warps) against the
# prototype's 48-52 (5 groups, 40 warps); the profile puts the gather's theoretical occupancy at 40.
set -u
G="bash scripts/gpu_run.sh run voxbreast"
o=$OUT
{
for opt in "" "-cl-nv-maxrregcount=56" "-cl-nv-maxrregcount=48" "" "-cl-nv-maxrregcount=48"; do
  echo "== options '$opt'"
  VOXBREAST_DUMP_KERNELS=/tmp/dk VOXBREAST_CL_OPTIONS="$opt -cl-nv-verbose" timeout 100 $G bench --device gpu --quick --no-study --sizes 80 115 --out $o/b 2>&1 | grep -E 'steps/s'
  grep -hE -A3 "Compiling entry function 'heun_(predict|correct)'" /tmp/dk/*log* 2>/dev/null | grep -E 'entry|registers|spill' | head -6
  rm -rf /tmp/dk
done
} 2>&1 | tee $o/main_caps_h200.txt
