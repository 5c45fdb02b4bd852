#!/usr/bin/env bash
# Session 28, device call 1 (H200): attempt 37, the march in column order (ORDER 8: the piece's TZ
# centres held, the 9 neighbouring columns visited in turn) against the lean plane march (5) and
# the gather (0), registers from ptxas; Nsight Compute on the gather and ORDER 8 at TZ 2 and 4.
set -u
d=docs/results/session28
o=$OUT
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1"
NCU=/usr/local/cuda/bin/ncu
mkdir -p $o/ptx
{
PROTO_PTX=$o/ptx PROTO_OPTS="$B" timeout 200 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 8:0:0:2:128 8:0:0:2:256 8:0:0:3:128 8:0:0:4:128 8:0:0:4:256 8:0:0:6:128" 2>&1 | grep -E 'order|program|Used [0-9]+ reg' | grep -v 'Used 14 reg'
PROTO_OPTS="$B" timeout 60 $P 80 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 8:0:0:2:128 8:0:0:4:128"
PROTO_OPTS="$B" timeout 60 $P 160 1000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 8:0:0:2:128 8:0:0:4:128"
/usr/local/cuda/bin/nvcc -O2 -o /tmp/ncu_host docs/results/session27/ncu_host.cpp -lcuda
S="--section SpeedOfLight --section ComputeWorkloadAnalysis --section MemoryWorkloadAnalysis --section Occupancy --section WarpStateStats --section InstructionStats --section SchedulerStats"
timeout 80 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/ptx/program1.ptx $o/ptx/program2.ptx 115 8 256 > $o/ncu_gather.txt 2>&1
timeout 80 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/ptx/program5.ptx $o/ptx/program6.ptx 115 8 128 > $o/ncu_col2.txt 2>&1
timeout 80 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/ptx/program11.ptx $o/ptx/program12.ptx 115 8 128 > $o/ncu_col4.txt 2>&1
for f in $o/ncu_gather.txt $o/ncu_col2.txt $o/ncu_col4.txt; do echo "== $f"; grep -E 'ncu_host|Duration|L1/TEX Cache Throughput|L2 Cache Throughput|DRAM Throughput|Issue Slots Busy|Executed Instructions  |Registers Per|Achieved Active|Warp Cycles Per Issued' $f; done
} 2>&1 | tee $o/column_h200.txt
