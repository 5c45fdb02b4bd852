#!/usr/bin/env bash
# Session 27, device call 7 (H200): attempt 36d, the lean connection (LEAN=1) in the gather and in
# the march, timed against call 2's forms; Nsight Compute on the lean gather and lean march (TZ 4).
set -u
d=docs/results/session27
o=$OUT
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero"
NCU=/usr/local/cuda/bin/ncu
mkdir -p $o/ptx
{
timeout 100 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 5:0:0:4:256"
echo "== lean"
PROTO_PTX=$o/ptx PROTO_OPTS="$B -DLEAN=1" timeout 100 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 5:0:0:4:256 5:0:0:23:128" 2>&1 | grep -E 'order|program|Used'
/usr/local/cuda/bin/nvcc -O2 -o /tmp/ncu_host $d/ncu_host.cpp -lcuda
S="--section SpeedOfLight --section ComputeWorkloadAnalysis --section MemoryWorkloadAnalysis --section Occupancy --section WarpStateStats --section InstructionStats --section SchedulerStats"
timeout 100 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/ptx/program1.ptx $o/ptx/program2.ptx 115 8 256 > $o/ncu_lean_gather.txt 2>&1
timeout 100 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/ptx/program3.ptx $o/ptx/program4.ptx 115 8 128 > $o/ncu_lean_march4.txt 2>&1
for f in $o/ncu_lean_gather.txt $o/ncu_lean_march4.txt; do echo "== $f"; grep -E 'ncu_host|Duration|L1/TEX Cache Throughput|L2 Cache Throughput|DRAM Throughput|Issue Slots Busy|Executed Instructions  |Registers Per|Achieved Active|Warp Cycles Per Issued' $f; done
} 2>&1 | tee $o/lean_h200.txt
