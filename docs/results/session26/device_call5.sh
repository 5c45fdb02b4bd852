#!/usr/bin/env bash
# Session 26, device call 5 (H200): the PTX and registers of main's 1.5M cube step (heun_predict,
# heun_correct with the predicted stage packed, groups of 256) and of the prototype's stage pair,
# to compare instruction by instruction (call 4: main 12% slower in the same call).
set -u
G="bash scripts/gpu_run.sh run"
mkdir -p $OUT/ptx_main $OUT/ptx_proto
VOXBREAST_CL_OPTIONS="-cl-nv-verbose" VOXBREAST_DUMP_KERNELS=$OUT/ptx_main timeout 100 $G voxbreast bench --device gpu --quick --no-study --sizes 115 --out /tmp/b 2>&1 | grep steps/s
PROTO_OPTS="-cl-std=CL1.2 -cl-mad-enable -cl-denorms-are-zero" PROTO_PTX=$OUT/ptx_proto timeout 100 $G .device-pkgs/proto_tile 115 2000 docs/results/session26/proto_tile.cl "0:0:0:0:256" 2>&1 | grep -E "order|registers|Compiling" | sed -E 's/  +/ /g'
grep -h -E "Compiling entry|registers" $OUT/ptx_main/*.log | grep -A1 "heun_predict\|heun_correct"
ls -la $OUT/ptx_main $OUT/ptx_proto
