#!/usr/bin/env bash
# Session 29, device call 3 (H200): attempt 39 (the general connection loop as s·r) against the
# build before it (old_bundle.tar.xz, d9891ff) in alternating quick rows (the 36k breast, the
# 1.5M phantom, the 1.5M cube: linear springs, Heun, float); the GPU tests; Nsight Compute on the
# prototype's MIN gather and ORDER 10 (attempt 38b).
# The harness: patch -o proto_sym.cpp docs/results/session27/proto_march.cpp proto_sym.cpp.patch;
# g++ -O2 -std=c++20 proto_sym.cpp -o .device-proto/proto_sym -lOpenCL. (These calls ran the two
# kernel files as one, the same text; they were split afterwards.)
set -u
d=docs/results/session29
o=$OUT
NCU=/usr/local/cuda/bin/ncu
old() {  # the old build, run as scripts/gpu_run.sh runs the new one
  local t; t=$(mktemp -d); tar -C "$t" -xJf .device-pkgs/old_bundle.tar.xz
  for deb in .device-pkgs/deb/*.deb; do dpkg -x "$deb" "$t/root"; done
  mkdir -p "$t/icd"; echo "libnvidia-opencl.so.1" > "$t/icd/nvidia.icd"
  OCL_ICD_VENDORS=$t/icd LD_LIBRARY_PATH=$t/root/usr/lib/x86_64-linux-gnu:$t/lib "$t/bin/voxbreast" "$@"
}
Q="bench --device gpu --quick --no-study --breast --breast-large --sizes 115"
{
for i in 1 2; do
  echo "== old"; old $Q --out /tmp/bo 2>&1 | grep -E "^(block|breast)"
  echo "== new"; bash scripts/gpu_run.sh run voxbreast $Q --out /tmp/bn 2>&1 | grep -E "^(block|breast)"
done
echo "== GPU tests"
VOXBREAST_DEVICE=gpu timeout 240 bash scripts/gpu_run.sh run test_physics --gtest_brief=1 2>&1 | tail -15
# the prototype under Nsight Compute: the MIN gather and ORDER 10 (TY 6, TZ 8), every element free
t=$(mktemp -d); dpkg -x .device-proto/ocl-icd-libopencl1_*.deb $t/root
mkdir -p $t/icd && echo libnvidia-opencl.so.1 > $t/icd/nvidia.icd
mkdir -p /tmp/ptx
OCL_ICD_VENDORS=$t/icd LD_LIBRARY_PATH=$t/root/usr/lib/x86_64-linux-gnu:$PWD/.device-proto PROTO_NOHELD=1 PROTO_INPLACE=1 PROTO_REVERSE=1 PROTO_PTX=/tmp/ptx \
  PROTO_OPTS="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1 -DNV=1 -DMIN=1" timeout 60 .device-proto/proto_sym 115 10 docs/results/session28/proto_march.cl+$d/proto_sym.cl "0:0:0:0:256 10:32:6:8:192" 2>&1 | grep -E "order|Used [0-9]+ reg" | grep -v "Used 14 reg"
/usr/local/cuda/bin/nvcc -O2 -o /tmp/ncu_host $d/ncu_host.cpp -lcuda
S="--section SpeedOfLight --section ComputeWorkloadAnalysis --section MemoryWorkloadAnalysis --section Occupancy --section WarpStateStats --section InstructionStats --section SchedulerStats"
NCU_NOHELD=1 NCU_INPLACE=1 timeout 90 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host /tmp/ptx/program1.ptx /tmp/ptx/program2.ptx 115 8 256 > $o/ncu_gather.txt 2>&1
NCU_NOHELD=1 NCU_INPLACE=1 NCU_BLOCKS=1380 timeout 90 $NCU $S --launch-skip 6 --launch-count 2 /tmp/ncu_host /tmp/ptx/program3.ptx /tmp/ptx/program4.ptx 115 8 192 > $o/ncu_order10.txt 2>&1
for f in $o/ncu_gather.txt $o/ncu_order10.txt; do echo "== $f"; grep -E 'ncu_host|Duration|L1/TEX Cache Throughput|DRAM Throughput|Issue Slots Busy|Executed Instructions  |Registers Per|Achieved Active|Warp Cycles Per Issued|Shared Memory|Stall|Barrier|shared' $f | head -40; done
} 2>&1 | tee $o/attempt39_call3_h200.txt
