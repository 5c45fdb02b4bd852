#!/usr/bin/env bash
# Session 27, device call 11 (H200): call 10's corrector-order question again with the caches left
# as the previous kernel leaves them (ncu --cache-control none, application replay: the order's
# whole point is what the predictor leaves in L2), the corrector in place as in main.
set -u
d=docs/results/session27
o=$OUT
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
NCU=/usr/local/cuda/bin/ncu
S="--cache-control none --replay-mode application --section SpeedOfLight --section MemoryWorkloadAnalysis"
mkdir -p $o/fwd $o/rev
PROTO_PTX=$o/fwd timeout 60 $P 64 20 $d/proto_march.cl "0:0:0:0:256" > /dev/null 2>&1
PROTO_PTX=$o/rev PROTO_REVERSE=1 timeout 60 $P 64 20 $d/proto_march.cl "0:0:0:0:256" > /dev/null 2>&1
/usr/local/cuda/bin/nvcc -O2 -o /tmp/ncu_host $d/ncu_host.cpp -lcuda
run() {  # name stage2.ptx N
  NCU_INPLACE=1 timeout 100 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/fwd/program1.ptx $2 $3 8 256 > $o/ncu_$1.txt 2>&1
  echo "== $1"
  grep -E 'Duration|DRAM Throughput|L2 Hit|L1/TEX Hit' $o/ncu_$1.txt
}
{
for N in 64 80 115; do run fwd_$N $o/fwd/program2.ptx $N; run rev_$N $o/rev/program2.ptx $N; done
} 2>&1 | tee $o/ncu_order_h200.txt
