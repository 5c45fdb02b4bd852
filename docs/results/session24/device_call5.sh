#!/usr/bin/env bash
# Session 24, device call 5 (H200): change 27 against the harness: why main gains 3% where the
# harness gained 12%. PTX and registers of both variants (64k cube: the packed path's smallest
# size), and the per-kernel device times of the 1.5M cube, packed off and on.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
for v in off on; do
  VOXBREAST_PRED_PACKED=$([ $v = on ] && echo 1 || echo 0) VOXBREAST_CL_OPTIONS="-cl-nv-verbose" VOXBREAST_DUMP_KERNELS=/tmp/ptx_$v \
    timeout 60 $G voxbreast bench --quick --no-study --sizes 40 --out /tmp/p >/dev/null 2>&1
  mkdir -p $o/ptx_$v && cp /tmp/ptx_$v/* $o/ptx_$v/ 2>/dev/null
done
ls $o/ptx_off $o/ptx_on
for v in off on; do
  echo "== $v"
  VOXBREAST_PRED_PACKED=$([ $v = on ] && echo 1 || echo 0) timeout 100 $G voxbreast bench --quick --no-study --sizes 115 --profile --out /tmp/t 2>&1 | tail -12
done 2>&1 | tee $o/profile_1.5M.txt
