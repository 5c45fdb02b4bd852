#!/usr/bin/env bash
# Session 29, device call 5 (H200): attempt 39b, which part of the general loop's s·r form
# (attempt 39) costs: one build with the parts behind build macros (attempt39b_variants.diff,
# switched by VOXBREAST_CL_OPTIONS): h·d's zero components dropped (VB_GL_HD), the |r|² floor
# for the select (VB_GL_FLOOR), s·r (VB_GL_SR); alternating quick rows of the 36k breast, the 1.5M
# phantom and the 1.5M cube, twice; registers of the stepping kernels of base and full form.
set -u
o=$OUT
Q="bench --device gpu --quick --no-study --breast --breast-large --sizes 115"
{
for i in 1 2; do
  for opt in "" "-DVB_GL_HD=1" "-DVB_GL_FLOOR=1" "-DVB_GL_HD=1 -DVB_GL_FLOOR=1" "-DVB_GL_SR=1 -DVB_GL_FLOOR=1" "-DVB_GL_SR=1 -DVB_GL_FLOOR=1 -DVB_GL_HD=1"; do
    echo "== options: '$opt'"
    VOXBREAST_CL_OPTIONS="$opt" bash scripts/gpu_run.sh run voxbreast $Q --out /tmp/b 2>&1 | grep -E "^(block|breast)"
  done
done
for opt in "" "-DVB_GL_SR=1 -DVB_GL_FLOOR=1 -DVB_GL_HD=1"; do
  rm -rf /tmp/dump; mkdir -p /tmp/dump
  echo "== registers, options: '$opt'"
  VOXBREAST_DUMP_KERNELS=/tmp/dump VOXBREAST_CL_OPTIONS="$opt -cl-nv-verbose" bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --breast --breast-large --out /tmp/b > /dev/null 2>&1
  grep -h -A3 "entry function '\(heun_\|persistent\)" /tmp/dump/*.log | grep -E "entry|Used" | paste - - | sed -e 's/ptxas info *: //g' | sort | uniq -c
done
} 2>&1 | tee $o/variants_call5_h200.txt
