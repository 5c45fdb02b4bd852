#!/usr/bin/env bash
# Session 27, device call 1 (H200): attempt 36, the march up columns (ORDER 4) against the gather
# (ORDER 0), 1.5M, 512k and 4.1M cubes; registers from ptxas (PROTO_PTX).
set -u
d=docs/results/session27
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
o=$OUT
mkdir -p $o/ptx
{
nvidia-smi --query-gpu=name,clocks.max.sm,power.limit --format=csv
PROTO_PTX=$o/ptx timeout 100 $P 115 300 $d/proto_march.cl "0:0:0:0:256 4:0:0:8:256" 2>&1 | grep -E 'registers|order|device'
timeout 200 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 4:0:0:4:256 4:0:0:8:256 4:0:0:8:128 4:0:0:12:128 4:0:0:16:128 4:0:0:23:128 4:0:0:16:64 0:0:0:0:256"
timeout 100 $P 80 2000 $d/proto_march.cl "0:0:0:0:256 4:0:0:8:128 4:0:0:16:128"
timeout 100 $P 160 1000 $d/proto_march.cl "0:0:0:0:256 4:0:0:8:128 4:0:0:16:128 4:0:0:32:128"
} 2>&1 | tee $o/march_h200.txt
