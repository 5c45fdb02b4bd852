#!/usr/bin/env bash
# Session 29, device call 1 (H200): attempt 38, each connection once (ORDER 9, proto_sym.cl)
# against the MIN and lean gathers (ORDER 0), every element free (PROTO_NOHELD=1), the corrector
# in place (PROTO_INPLACE=1; the gathers' corrector in reverse as main's); registers from ptxas.
# The harness: patch -o proto_sym.cpp docs/results/session27/proto_march.cpp proto_sym.cpp.patch;
# g++ -O2 -std=c++20 proto_sym.cpp -o .device-proto/proto_sym -lOpenCL. (These calls ran the two
# kernel files as one, the same text; they were split afterwards.)
set -u
d=docs/results/session29
t=$(mktemp -d)
dpkg -x .device-proto/ocl-icd-libopencl1_*.deb $t/root
mkdir -p $t/icd && echo libnvidia-opencl.so.1 > $t/icd/nvidia.icd
export OCL_ICD_VENDORS=$t/icd LD_LIBRARY_PATH=$t/root/usr/lib/x86_64-linux-gnu:$PWD/.device-proto
P=.device-proto/proto_sym
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1 -DNV=1"
export PROTO_NOHELD=1 PROTO_INPLACE=1 PROTO_REVERSE=1
{
nvidia-smi --query-gpu=name,clocks.max.sm,power.limit --format=csv
mkdir -p /tmp/ptx
PROTO_PTX=/tmp/ptx PROTO_OPTS="$B -DMIN=1" timeout 100 $P 115 10 docs/results/session28/proto_march.cl+$d/proto_sym.cl "9:32:4:16:128 9:32:8:16:256" 2>&1 | grep -E 'order|Used [0-9]+ reg|error|rror' | grep -v 'Used 14 reg'
for N in 115 80 64 160; do
  S=2000; [ $N = 160 ] && S=800
  echo "== N=$N"
  PROTO_OPTS="$B" timeout 100 $P $N $S docs/results/session28/proto_march.cl+$d/proto_sym.cl "0:0:0:0:256" 2>&1 | grep -E 'order|rror'
  PROTO_OPTS="$B -DMIN=1" timeout 200 $P $N $S docs/results/session28/proto_march.cl+$d/proto_sym.cl "0:0:0:0:256 9:32:4:8:128 9:32:4:16:128 9:32:4:32:128 9:32:6:16:192 9:32:8:8:256 9:32:8:16:256 9:32:8:32:256" 2>&1 | grep -E 'order|rror'
done
} 2>&1 | tee $OUT/sym_call1_h200.txt
