#!/usr/bin/env bash
# Session 25, device call 2 (H200): attempt 31, the neighbours' indices from the 8 row centres'
# grid entries and a presence mask (proto_walk.cl ROWS=1) against 26 grid reads, in layouts 0
# (main's state), 1 (all packed) and 5 (main today: the predicted stage packed); per-stage times.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
P=docs/results/session25/proto_walk.cl
{
timeout 120 $G .device-pkgs/proto_walk 115 2000 $P "5 1 0 5 1" "1" 128 "0 1"
timeout 80 $G .device-pkgs/proto_walk 80 4000 $P "5 1 5 1" "1" 128 "0 1"
} 2>&1 | tee $o/rows_h200.txt
