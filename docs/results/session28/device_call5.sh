#!/usr/bin/env bash
# Session 28, device call 5 (H200): attempt 37e, the column-order march (TZ 3, MIN) against the
# gather as main runs its stages: the corrector in place and in reverse (PROTO_INPLACE=1,
# PROTO_REVERSE=1), at 262k, 512k, 1.5M and 4.1M; Nsight Compute on the march.
set -u
d=docs/results/session28
o=$OUT
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1"
NCU=/usr/local/cuda/bin/ncu
mkdir -p $o/p1
{
for N in 115 64 80 160; do
  S=2000; [ $N = 160 ] && S=1000
  echo "== N=$N lean, in place, reverse"; PROTO_INPLACE=1 PROTO_REVERSE=1 PROTO_OPTS="$B" timeout 60 $P $N $S $d/proto_march.cl "0:0:0:0:256" | grep order
  echo "== N=$N MIN=1, in place, reverse"; PROTO_INPLACE=1 PROTO_REVERSE=1 PROTO_OPTS="$B -DMIN=1" timeout 60 $P $N $S $d/proto_march.cl "0:0:0:0:256 8:0:0:3:128" | grep order
  echo "== N=$N MIN=1, second buffer, in order"; PROTO_OPTS="$B -DMIN=1" timeout 60 $P $N $S $d/proto_march.cl "0:0:0:0:256 8:0:0:3:128" | grep order
done
PROTO_PTX=$o/p1 PROTO_OPTS="$B -DMIN=1" timeout 60 $P 115 10 $d/proto_march.cl "8:0:0:3:128" > /dev/null 2>&1
/usr/local/cuda/bin/nvcc -O2 -o /tmp/ncu_host docs/results/session27/ncu_host.cpp -lcuda
timeout 100 $NCU --set full --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/p1/program1.ptx $o/p1/program2.ptx 115 8 128 > $o/ncu_min1_col3_full.txt 2>&1
grep -E 'ncu_host|Duration|L1/TEX Cache Throughput|L2 Cache Throughput|DRAM Throughput|Issue Slots Busy|Executed Instructions  |Registers Per|Achieved Active|Warp Cycles Per Issued|Stall|stall' $o/ncu_min1_col3_full.txt | head -60
rm -rf $o/p1
} 2>&1 | tee $o/inplace_h200.txt
