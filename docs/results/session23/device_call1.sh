#!/usr/bin/env bash
# Session 23, device call 1 (H200): change 26, the short connection loop's arithmetic trimmed
# (one scalar s per connection, force s·r; the lattice offset added only where d has one).
# Variants of one build through VOXBREAST_CL_OPTIONS: -DVB_EXP_OLD=1 (main's loop as of 77ab52a),
# the new loop, and -DVB_EXP_SHIFT=1 (r = u_j − (u_i ∓ h): 3 instructions for r, one more
# rounding). 1.5M and 262k cubes, linear + Heun float, three rounds interleaved, --profile in the
# first; the PTX and register counts of each; GPU tests of the short loop and the kernels.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
nvidia-smi --query-gpu=name,driver_version,power.limit,clocks.max.sm --format=csv,noheader > $o/device.txt
VOXBREAST_DEVICE=gpu timeout 200 $G test_physics \
  --gtest_filter='*UniformPath*:*UniformNeighbourhood*:*KernelForces*:*KernelSteps*:*StepList*:*GravityFlip*' 2>&1 \
  | grep -E "^\[ +(OK|FAILED|PASSED) |tests? ran|Failure|error|short vs" > $o/gpu_tests.txt
tail -3 $o/gpu_tests.txt
for v in old new shift; do
  case $v in old) opt=-DVB_EXP_OLD=1;; new) opt=;; shift) opt=-DVB_EXP_SHIFT=1;; esac
  VOXBREAST_CL_OPTIONS="$opt -cl-nv-verbose" VOXBREAST_DUMP_KERNELS=/tmp/ptx_$v timeout 60 $G voxbreast bench --quick --no-study --sizes 20 --out /tmp/p >/dev/null 2>&1
  mkdir -p $o/ptx_$v && cp /tmp/ptx_$v/*.log $o/ptx_$v/ 2>/dev/null
  for b in /tmp/ptx_$v/*.bin; do
    echo "$v $(basename $b): heun_predict instructions $(awk '/\.entry heun_predict\(/,/^}/' $b | grep -cE '^\s+[a-z@]')"
  done
done 2>&1 | tee $o/ptx_counts.txt
run() {  # label, env..., then bench arguments after --
  local label=$1; shift; local envs=(); while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
  echo "== $label"; env "${envs[@]}" timeout 100 $G voxbreast bench --quick --no-study "$@" --out /tmp/t 2>&1 | grep -E "^(breast|block)|device|host"
  { echo "# $label"; cat /tmp/t/throughput.csv; } >> $o/trim.csv
}
{
for r in 1 2 3; do
  p=; [ $r = 1 ] && p=--profile
  run "r$r old" VOXBREAST_CL_OPTIONS=-DVB_EXP_OLD=1 -- --sizes 64 115 $p
  run "r$r new" X=1 -- --sizes 64 115 $p
  run "r$r shift" VOXBREAST_CL_OPTIONS=-DVB_EXP_SHIFT=1 -- --sizes 64 115 $p
done
} 2>&1 | tee $o/trim.txt
