#!/usr/bin/env bash
# Session 28, device call 9 (H200): change 30, the short loop's connection as s·r (fewer
# instructions), against the build before it (old_bundle.tar.xz, 9b269f5) in alternating quick
# rows at 512k and 1.5M; main's new stage pair under Nsight Compute (vb_args_shim, main_host);
# the GPU tests of the short loop.
set -u
d=docs/results/session28
o=$OUT
NCU=/usr/local/cuda/bin/ncu
old() {  # the old build, run as scripts/gpu_run.sh runs the new one
  local t; t=$(mktemp -d); tar -C "$t" -xJf .device-pkgs/old_bundle.tar.xz
  for deb in .device-pkgs/deb/*.deb; do dpkg -x "$deb" "$t/root"; done
  mkdir -p "$t/icd"; echo "libnvidia-opencl.so.1" > "$t/icd/nvidia.icd"
  OCL_ICD_VENDORS=$t/icd LD_LIBRARY_PATH=$t/root/usr/lib/x86_64-linux-gnu:$t/lib "$t/bin/voxbreast" "$@"
}
Q="bench --device gpu --quick --no-study --sizes 80 115"
{
for i in 1 2; do
  echo "== old"; old $Q --out /tmp/bo 2>&1 | grep -E "^block"
  echo "== new"; bash scripts/gpu_run.sh run voxbreast $Q --out /tmp/bn 2>&1 | grep -E "^block"
done
mkdir -p /tmp/args /tmp/dump
VBSHIM_DIR=/tmp/args VBSHIM_AT=300 VOXBREAST_DUMP_KERNELS=/tmp/dump VOXBREAST_CL_OPTIONS=-cl-nv-verbose timeout 120 bash scripts/gpu_run.sh run env LD_PRELOAD=$PWD/.device-pkgs/vb_args_shim.so voxbreast bench --device gpu --quick --no-study --sizes 115 --out /tmp/b 2>&1 | grep -E "shim|block"
prog=$(grep -l "heun_predict" /tmp/dump/*.bin | head -1)
grep -A4 "entry function 'heun_" /tmp/dump/*.log | grep -E "entry|Used"
/usr/local/cuda/bin/nvcc -O2 -o /tmp/main_host $d/main_host.cpp -lcuda
timeout 60 /tmp/main_host $prog /tmp/args 20
timeout 150 $NCU --set full --launch-skip 4 --launch-count 2 /tmp/main_host $prog /tmp/args 4 > $o/ncu_main30_full.txt 2>&1
grep -E 'Duration|L1/TEX Cache Throughput|L2 Cache Throughput|DRAM Throughput|Issue Slots Busy|Executed Instructions  |Registers Per|Achieved Active|Warp Cycles Per Issued|L1/TEX Hit' $o/ncu_main30_full.txt
VOXBREAST_DEVICE=gpu timeout 200 bash scripts/gpu_run.sh run test_physics --gtest_brief=1 --gtest_filter='UniformPath*:UniformNeighbourhood*:CorrectOrder*:StepWorkGroup*' 2>&1 | tail -12
} 2>&1 | tee $o/change30_h200.txt
