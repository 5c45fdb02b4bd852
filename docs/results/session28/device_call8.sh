#!/usr/bin/env bash
# Session 28, device call 8 (H200): main's own stepping kernels under Nsight Compute at last.
# vb_args_shim.so records heun_predict's and heun_correct's arguments and buffers from a quick
# bench run of the 1.5M cube (300th step); main_host runs main's PTX with them; ncu profiles
# main's stage pair next to the prototype's lean gather in the same configuration (corrector in
# place and reversed).
set -u
d=docs/results/session28
o=$OUT
NCU=/usr/local/cuda/bin/ncu
S="--set full"
mkdir -p /tmp/args /tmp/dump /tmp/pp
{
VBSHIM_DIR=/tmp/args VBSHIM_AT=300 VOXBREAST_DUMP_KERNELS=/tmp/dump timeout 120 bash scripts/gpu_run.sh run env LD_PRELOAD=$PWD/.device-pkgs/vb_args_shim.so voxbreast bench --device gpu --quick --no-study --sizes 115 --out /tmp/b 2>&1 | grep -E "shim|block"
cp /tmp/args/manifest.txt $o/manifest.txt
prog=$(grep -l "heun_predict" /tmp/dump/*.bin | head -1); echo "program $prog"
/usr/local/cuda/bin/nvcc -O2 -o /tmp/main_host $d/main_host.cpp -lcuda
timeout 60 /tmp/main_host $prog /tmp/args 20
timeout 150 $NCU $S --launch-skip 4 --launch-count 2 /tmp/main_host $prog /tmp/args 4 > $o/ncu_main_full.txt 2>&1
PROTO_PTX=/tmp/pp PROTO_REVERSE=1 PROTO_OPTS="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1" timeout 60 bash scripts/gpu_run.sh run .device-pkgs/proto_march 115 10 $d/proto_march.cl "0:0:0:0:256" > /dev/null 2>&1
/usr/local/cuda/bin/nvcc -O2 -o /tmp/ncu_host docs/results/session27/ncu_host.cpp -lcuda
NCU_INPLACE=1 timeout 150 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host /tmp/pp/program1.ptx /tmp/pp/program2.ptx 115 8 256 > $o/ncu_proto_inplace_full.txt 2>&1
for f in $o/ncu_main_full.txt $o/ncu_proto_inplace_full.txt; do echo "== $f"; grep -E '  [a-z_]+\(|Duration|L1/TEX Cache Throughput|L2 Cache Throughput|DRAM Throughput|Issue Slots Busy|Executed Instructions  |Registers Per|Achieved Active|Warp Cycles Per Issued|L1/TEX Hit|L2 Hit|Mem Busy|Max Bandwidth' $f; done
} 2>&1 | tee $o/main_ncu_h200.txt
