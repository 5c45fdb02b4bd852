#!/usr/bin/env bash
# Session 27, device call 14 (H200): main's step with every element on the short loop, the general
# loop compiled out (timing only: a build of main with the hook `VB_EXP_UNIFORM_ONLY` in
# lattice_force_pending, not committed; wrong forces for the cube's few non-uniform blocks), to
# see whether the general loop's registers (main 60-61 against the prototype's 48-52) are main's
# gap to the prototype.
set -u
G="bash scripts/gpu_run.sh run voxbreast"
o=$OUT
{
for opt in "" "-DVB_EXP_UNIFORM_ONLY" "" "-DVB_EXP_UNIFORM_ONLY"; do
  echo "== options '$opt'"
  VOXBREAST_DUMP_KERNELS=/tmp/dk VOXBREAST_CL_OPTIONS="$opt -cl-nv-verbose" timeout 100 $G bench --device gpu --quick --no-study --sizes 80 115 --out $o/b 2>&1 | grep -E 'steps/s'
  grep -hE -A3 "Compiling entry function 'heun_(predict|correct)'" /tmp/dk/*log* 2>/dev/null | grep -E 'entry|registers|spill' | head -6
  rm -rf /tmp/dk
done
} 2>&1 | tee $o/uniform_only_h200.txt
