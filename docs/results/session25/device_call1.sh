#!/usr/bin/env bash
# Session 25, device call 1 (H200): attempt 30, each work-group steps WALK consecutive blocks
# (proto_walk.cl): do the neighbour rows a block reads come cheaper from L1 when the same group
# read them for the block before? Layouts 0 (main) and 1 (packed), 1.5M and 512k cubes.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
P=docs/results/session25/proto_walk.cl
{
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,power.limit --format=csv
timeout 150 $G .device-pkgs/proto_walk 115 2000 $P "0 1" "1 2 4 8 11 12 16 32 1"
timeout 80 $G .device-pkgs/proto_walk 115 2000 $P "1" "1 4 8 16" 256
timeout 80 $G .device-pkgs/proto_walk 80 4000 $P "0 1" "1 4 8 16 1"
} 2>&1 | tee $o/walk_h200.txt
