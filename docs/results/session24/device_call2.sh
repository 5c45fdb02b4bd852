#!/usr/bin/env bash
# Session 24, device call 2 (H200): attempt 29, main's short connection loop with the state in
# five layouts (proto_layout.cl): do the neighbour reads cost by the cache lines a warp's load
# touches? 1.5M and 512k cubes, two rounds interleaved.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
P=docs/results/session24/proto_layout.cl
{
timeout 100 $G .device-pkgs/proto_layout 115 2000 $P "0 1 2 3 4 0 1 2 3 4"
timeout 60 $G .device-pkgs/proto_layout 80 4000 $P "0 1 2 3 4 0"
} 2>&1 | tee $o/layout_h200.txt
