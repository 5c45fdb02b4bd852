#!/usr/bin/env bash
# Session 27, device call 10 (H200): two open questions under Nsight Compute (ncu_host.cpp): why
# work-groups of 256 beat 128 at 1.5M (change 28), and why the corrector walked in reverse costs
# ~3% at 262k (change 29's threshold); the prototype's gather stage pair.
set -u
d=docs/results/session27
o=$OUT
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
NCU=/usr/local/cuda/bin/ncu
S="--section SpeedOfLight --section MemoryWorkloadAnalysis --section Occupancy --section SchedulerStats --section WarpStateStats --section LaunchStats"
mkdir -p $o/fwd $o/rev
PROTO_PTX=$o/fwd timeout 60 $P 64 20 $d/proto_march.cl "0:0:0:0:256" > /dev/null 2>&1
PROTO_PTX=$o/rev PROTO_REVERSE=1 timeout 60 $P 64 20 $d/proto_march.cl "0:0:0:0:256" > /dev/null 2>&1
/usr/local/cuda/bin/nvcc -O2 -o /tmp/ncu_host $d/ncu_host.cpp -lcuda
run() {  # name stage1.ptx stage2.ptx N WG
  timeout 100 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $2 $3 $4 8 $5 > $o/ncu_$1.txt 2>&1
  echo "== $1"
  grep -E 'Duration|L1/TEX Cache Throughput|L2 Cache Throughput|DRAM Throughput|Issue Slots Busy|L1/TEX Hit|L2 Hit|Achieved Active|Waves Per SM|Eligible Warps' $o/ncu_$1.txt
}
{
run wg128_115 $o/fwd/program1.ptx $o/fwd/program2.ptx 115 128
run wg256_115 $o/fwd/program1.ptx $o/fwd/program2.ptx 115 256
run fwd_64 $o/fwd/program1.ptx $o/fwd/program2.ptx 64 256
run rev_64 $o/fwd/program1.ptx $o/rev/program2.ptx 64 256
run fwd_115 $o/fwd/program1.ptx $o/fwd/program2.ptx 115 256
run rev_115 $o/fwd/program1.ptx $o/rev/program2.ptx 115 256
} 2>&1 | tee $o/ncu_questions_h200.txt
