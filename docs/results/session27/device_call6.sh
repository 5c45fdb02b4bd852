#!/usr/bin/env bash
# Session 27, device call 6 (H200): call 5 again, the PTX made loadable (OpenCL's global offset
# register zeroed, its texture mode dropped; ptxas's own errors printed if the JIT refuses it).
set -u
d=docs/results/session27
o=$OUT
NCU=/usr/local/cuda/bin/ncu
mkdir -p $o/ptx
{
PROTO_PTX=$o/ptx timeout 60 bash scripts/gpu_run.sh run .device-pkgs/proto_march 115 50 $d/proto_march.cl "0:0:0:0:256" 2>&1 | grep -E 'order'
/usr/local/cuda/bin/nvcc -O2 -o /tmp/ncu_host $d/ncu_host.cpp -lcuda
for i in 1 2; do sed -e 's/%envreg3/0/' -e 's/, texmode_independent//' $o/ptx/program$i.ptx > /tmp/p$i.ptx; /usr/local/cuda/bin/ptxas -arch=sm_90 /tmp/p$i.ptx -o /tmp/p$i.cubin 2>&1 | head -5; done
/tmp/ncu_host $o/ptx/program1.ptx $o/ptx/program2.ptx 115 20 256
timeout 200 $NCU --set full --launch-skip 6 --launch-count 2 /tmp/ncu_host $o/ptx/program1.ptx $o/ptx/program2.ptx 115 8 256 > $o/ncu_gather_full.txt 2>&1
echo "ncu rc $?"
grep -E 'Duration|Throughput|Hit Rate|Registers|Achieved Occupancy|Theoretical Occupancy|Issue Slots|Issued Ipc|Eligible|Warp Cycles Per Issued|No Eligible|Active Warps|Executed Ipc|SM Frequency|DRAM Frequency|Pipe|Bottleneck|bound|Stall' $o/ncu_gather_full.txt | head -120
} 2>&1 | tee $o/ncu_call6.txt
