#!/usr/bin/env bash
# Session 29, device call 2 (H200): attempt 38b, ORDER 10 (ORDER 9 with its global reads prefetched)
# against the MIN gather (ORDER 0), every element free (PROTO_NOHELD=1), the corrector
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
mkdir -p /tmp/ptx
PROTO_PTX=/tmp/ptx PROTO_OPTS="$B -DMIN=1" timeout 100 $P 115 10 docs/results/session28/proto_march.cl+$d/proto_sym.cl "10:32:4:8:128 10:32:7:12:224" 2>&1 | grep -E 'order|Used [0-9]+ reg|error|rror' | grep -v 'Used 14 reg'
for N in 115 80 160; do
  S=2000; [ $N = 160 ] && S=800
  echo "== N=$N"
  PROTO_OPTS="$B -DMIN=1" timeout 200 $P $N $S docs/results/session28/proto_march.cl+$d/proto_sym.cl "0:0:0:0:256 10:32:4:8:128 10:32:4:12:128 10:32:4:16:128 10:32:6:8:192 10:32:6:12:192 10:32:7:8:224 10:32:7:10:224 10:32:7:12:224 10:32:7:16:224 9:32:4:8:128" 2>&1 | grep -E 'order|rror'
done
} 2>&1 | tee $OUT/sym_call2_h200.txt
