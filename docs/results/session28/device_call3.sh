#!/usr/bin/env bash
# Session 28, device call 3 (H200): call 2 again with the prototype's abs() fixed (each
# direction's class folded at compile time) and MIN's rest vector h·d − ui per element
# (attempt 37c); Nsight Compute on the MIN=1 and MIN=2 gathers.
set -u
d=docs/results/session28
o=$OUT
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1"
NCU=/usr/local/cuda/bin/ncu
mkdir -p $o/p0 $o/p1 $o/p2
{
echo "== lean"; PROTO_PTX=$o/p0 PROTO_OPTS="$B" timeout 150 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 8:0:0:2:128 8:0:0:3:128" 2>&1 | grep -E '^order|Used [0-9]+ reg' | grep -v 'Used 14 reg'
echo "== MIN=1"; PROTO_PTX=$o/p1 PROTO_OPTS="$B -DMIN=1" timeout 150 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 8:0:0:2:128 8:0:0:3:128 0:0:0:0:128" 2>&1 | grep -E '^order|Used [0-9]+ reg' | grep -v 'Used 14 reg'
echo "== MIN=2"; PROTO_PTX=$o/p2 PROTO_OPTS="$B -DMIN=2" timeout 100 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 0:0:0:0:128" 2>&1 | grep -E '^order|Used [0-9]+ reg' | grep -v 'Used 14 reg'
for m in 0 1 2; do for N in 80 160; do echo "== MIN=$m N=$N"; PROTO_OPTS="$B -DMIN=$m" timeout 60 $P $N 1000 $d/proto_march.cl "0:0:0:0:256 8:0:0:3:128" | grep order; done; done
/usr/local/cuda/bin/nvcc -O2 -o /tmp/ncu_host docs/results/session27/ncu_host.cpp -lcuda
S="--section SpeedOfLight --section ComputeWorkloadAnalysis --section MemoryWorkloadAnalysis --section Occupancy --section WarpStateStats --section InstructionStats --section SchedulerStats"
timeout 80 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/p0/program1.ptx $o/p0/program2.ptx 115 8 256 > $o/ncu_lean_gather.txt 2>&1
timeout 80 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/p1/program1.ptx $o/p1/program2.ptx 115 8 256 > $o/ncu_min1_gather.txt 2>&1
timeout 80 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/p2/program1.ptx $o/p2/program2.ptx 115 8 256 > $o/ncu_min2_gather.txt 2>&1
for f in $o/ncu_lean_gather.txt $o/ncu_min1_gather.txt $o/ncu_min2_gather.txt; do echo "== $f"; grep -E 'ncu_host|Duration|L1/TEX Cache Throughput|L2 Cache Throughput|DRAM Throughput|Issue Slots Busy|Executed Instructions  |Registers Per|Achieved Active|Warp Cycles Per Issued' $f; done
tar -C $o -czf $o/ptx.tgz p0 p1 p2 && rm -rf $o/p0 $o/p1 $o/p2
} 2>&1 | tee $o/fixed_h200.txt
