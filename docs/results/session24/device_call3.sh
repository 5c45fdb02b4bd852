#!/usr/bin/env bash
# Session 24, device call 3 (H200): attempt 29 continued: layout 5, the state as on main (layout 0)
# and only Heun's predicted stage packed (layout 1), against 0 and 1; 1.5M and 512k cubes.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
P=docs/results/session24/proto_layout.cl
{
timeout 100 $G .device-pkgs/proto_layout 115 2000 $P "0 1 5 0 1 5"
timeout 60 $G .device-pkgs/proto_layout 80 4000 $P "0 1 5 0 1 5"
} 2>&1 | tee $o/layout_mixed_h200.txt
