#!/usr/bin/env bash
# Session 25, device call 4 (H200): attempt 32, row ends by warp shuffles (proto_walk.cl SHFL,
# "rows 2") against 26 grid reads ("rows 0") and row centres alone ("rows 1"), layouts 5 (main
# today), 1 (all packed) and 0; registers of the shuffle form.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
P=docs/results/session25/proto_walk.cl
mkdir -p $o/ptx
PROTO_PTX=$o/ptx timeout 60 $G .device-pkgs/proto_walk 40 100 $P "5 1" "1" 128 "2" 2>&1 | grep -E "registers|steps/s|rror" | tee $o/shfl_registers_h200.txt
{
timeout 150 $G .device-pkgs/proto_walk 115 2000 $P "5 1 0 5 1" "1" 128 "0 1 2"
timeout 100 $G .device-pkgs/proto_walk 80 4000 $P "5 1 5 1" "1" 128 "0 2"
} 2>&1 | tee $o/shfl_h200.txt
