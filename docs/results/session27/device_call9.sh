#!/usr/bin/env bash
# Session 27, device call 9 (H200): attempt 36e, the lean march with computed indices (ORDER 6, no
# grid reads: an upper bound for dense blocks) against the lean march (5) and the gather (0).
set -u
d=docs/results/session27
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1"
{
PROTO_PTX=/tmp PROTO_OPTS="$B" timeout 100 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 6:0:0:2:128 6:0:0:4:128 6:0:0:4:256 6:0:0:8:128" 2>&1 | grep -E 'order|Used [0-9]+ reg' | grep -v 'Used 14 reg'
PROTO_OPTS="$B" timeout 60 $P 80 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 6:0:0:4:128"
PROTO_OPTS="$B" timeout 60 $P 160 1000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 6:0:0:4:128"
} 2>&1 | tee $OUT/computed_h200.txt
