#!/usr/bin/env bash
# Session 27, device call 12 (H200): attempt 36f, the lean march with two work-items per column
# piece (ORDER 7, half a plane's cells each, forces summed by a butterfly shuffle) against the
# lean march (5) and the gather (0); registers from ptxas.
set -u
d=docs/results/session27
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1 -DNV_SHFL"
{
PROTO_PTX=/tmp PROTO_OPTS="$B" timeout 150 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 7:0:0:2:128 7:0:0:4:128 7:0:0:4:256 7:0:0:6:128 7:0:0:8:128 7:0:0:8:256 7:0:0:12:128" 2>&1 | grep -E 'order|Used [0-9]+ reg' | grep -v 'Used 14 reg'
PROTO_OPTS="$B" timeout 60 $P 80 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 7:0:0:4:128 7:0:0:8:128"
PROTO_OPTS="$B" timeout 60 $P 160 1000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 7:0:0:4:128 7:0:0:8:128"
} 2>&1 | tee $OUT/pair_h200.txt
