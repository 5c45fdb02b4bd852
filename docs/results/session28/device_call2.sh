#!/usr/bin/env bash
# Session 28, device call 2 (H200): attempt 37b, the connection in fewer instructions (MIN=1:
# coefficients per element, s = k − kL/|r| + c(Δv·r)/|r|²; MIN=2: and no masks or selects for
# elements with all 26 neighbours) in the gather (0) and the column-order march (8), against the
# lean gather; Nsight Compute on the MIN=2 gather and the MIN=1 march at TZ 2.
set -u
d=docs/results/session28
o=$OUT
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1"
NCU=/usr/local/cuda/bin/ncu
mkdir -p $o/p0 $o/p1 $o/p2
{
echo "== lean"; PROTO_PTX=$o/p0 PROTO_OPTS="$B" timeout 100 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128" 2>&1 | grep -E '^order|Used [0-9]+ reg' | grep -v 'Used 14 reg'
echo "== MIN=1"; PROTO_PTX=$o/p1 PROTO_OPTS="$B -DMIN=1" timeout 150 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 8:0:0:2:128 8:0:0:3:128 0:0:0:0:128" 2>&1 | grep -E '^order|Used [0-9]+ reg' | grep -v 'Used 14 reg'
echo "== MIN=2"; PROTO_PTX=$o/p2 PROTO_OPTS="$B -DMIN=2" timeout 100 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 0:0:0:0:128" 2>&1 | grep -E '^order|Used [0-9]+ reg' | grep -v 'Used 14 reg'
for m in 0 1 2; do for N in 80 160; do echo "== MIN=$m N=$N"; PROTO_OPTS="$B -DMIN=$m" timeout 60 $P $N 1000 $d/proto_march.cl "0:0:0:0:256" | grep order; done; done
/usr/local/cuda/bin/nvcc -O2 -o /tmp/ncu_host docs/results/session27/ncu_host.cpp -lcuda
S="--section SpeedOfLight --section ComputeWorkloadAnalysis --section MemoryWorkloadAnalysis --section Occupancy --section WarpStateStats --section InstructionStats --section SchedulerStats"
timeout 80 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/p2/program1.ptx $o/p2/program2.ptx 115 8 256 > $o/ncu_min2_gather.txt 2>&1
timeout 80 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/p1/program3.ptx $o/p1/program4.ptx 115 8 128 > $o/ncu_min1_col2.txt 2>&1
for f in $o/ncu_min2_gather.txt $o/ncu_min1_col2.txt; do echo "== $f"; grep -E 'ncu_host|Duration|L1/TEX Cache Throughput|L2 Cache Throughput|DRAM Throughput|Issue Slots Busy|Executed Instructions  |Registers Per|Achieved Active|Warp Cycles Per Issued' $f; done
tar -C $o -czf $o/ptx.tgz p0 p1 p2 && rm -rf $o/p0 $o/p1 $o/p2
} 2>&1 | tee $o/min_h200.txt
