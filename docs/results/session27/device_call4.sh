#!/usr/bin/env bash
# Session 27, device call 4 (H200): Nsight Compute (found on the machine in call 3) on the
# prototype's gather stages and on main's heun_predict / heun_correct at 1.5M (quick bench row).
set -u
d=docs/results/session27
G="bash scripts/gpu_run.sh run"
o=$OUT
NCU=/usr/local/cuda/bin/ncu
{
$NCU --version
timeout 150 $G $NCU --target-processes all --kernel-name regex:stage --launch-skip 20 --launch-count 2 --set full \
  .device-pkgs/proto_march 115 30 $d/proto_march.cl "0:0:0:0:256" 2>&1 | tail -400
} > $o/ncu_proto_h200.txt 2>&1
{
timeout 250 $G $NCU --target-processes all --kernel-name regex:heun --launch-skip 400 --launch-count 2 --set full \
  voxbreast bench --device gpu --quick --no-study --sizes 115 --out $o/b 2>&1 | tail -500
} > $o/ncu_main_h200.txt 2>&1
head -c 3000 $o/ncu_proto_h200.txt; grep -E 'Throughput|Pipe|Stall|Occupancy|Hit Rate|Duration|Registers|Warp Cycles|Issued|Eligible' $o/ncu_main_h200.txt | head -80
