#!/usr/bin/env bash
# Session 24, device call 8 (H200): change 27's heun_predict, 3 µs slower packed at 1.5M (call 5):
# its registers (ptxas, -cl-nv-verbose) packed and not, and the per-kernel device times of three
# more rounds, interleaved.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
for v in off on; do
  VOXBREAST_PRED_PACKED=$([ $v = on ] && echo 1 || echo 0) VOXBREAST_CL_OPTIONS="-cl-nv-verbose" VOXBREAST_DUMP_KERNELS=/tmp/ptx_$v \
    timeout 60 $G voxbreast bench --quick --no-study --sizes 40 --out /tmp/p >/dev/null 2>&1
  echo "== $v"; cat /tmp/ptx_$v/*.log | grep -B1 -A2 "heun_predict\|heun_correct" | grep -E "Function properties|Compiling|registers" | head -12
done 2>&1 | tee $o/registers.txt
for r in 1 2 3; do for v in off on; do
  echo "== r$r $v"
  VOXBREAST_PRED_PACKED=$([ $v = on ] && echo 1 || echo 0) timeout 100 $G voxbreast bench --quick --no-study --sizes 115 --profile --out /tmp/t 2>&1 | grep -E "heun_|device alone|steps/s"
done; done 2>&1 | tee $o/profile_rounds.txt
