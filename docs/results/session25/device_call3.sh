#!/usr/bin/env bash
# Session 25, device call 3 (H200): why main's 1.5M step (device alone ~188 µs) is slower than the
# prototype's same stage pair (layout 5, ~167 µs): the prototype's registers and PTX, and main's
# step with only the short loop compiled (VB_EXP_SHORT_ONLY, timing only), registers and times.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
P=docs/results/session25/proto_walk.cl
mkdir -p $o/ptx
PROTO_PTX=$o/ptx timeout 120 $G .device-pkgs/proto_walk 115 2000 $P "5 1" "1" 128 "0 1" 2>&1 | tee $o/proto_registers_h200.txt | grep -E "registers|steps/s|Compiling"
for v in main short; do
  opt=$([ $v = short ] && echo "-DVB_EXP_SHORT_ONLY=1" || echo "")
  VOXBREAST_CL_OPTIONS="$opt -cl-nv-verbose" VOXBREAST_DUMP_KERNELS=$o/ptx_$v \
    timeout 60 $G voxbreast bench --quick --no-study --sizes 40 --out /tmp/p >/dev/null 2>&1
  echo "== $v"; cat $o/ptx_$v/*.log | grep -B1 -A2 "heun_predict\|heun_correct" | grep -E "Compiling|registers" | head -8
done 2>&1 | tee $o/main_registers_h200.txt
for r in 1 2; do for v in main short; do
  echo "== r$r $v"
  opt=$([ $v = short ] && echo "-DVB_EXP_SHORT_ONLY=1" || echo "")
  VOXBREAST_CL_OPTIONS="$opt" timeout 100 $G voxbreast bench --quick --no-study --sizes 115 --profile --out /tmp/t 2>&1 | grep -E "heun_|device alone|steps/s"
done; done 2>&1 | tee $o/short_only_h200.txt
