#!/usr/bin/env bash
# Session 27, device call 2 (H200): attempt 36b, the march without branches (ORDER 5), with and
# without restrict, against the gather (ORDER 0), 1.5M cube; registers from ptxas.
set -u
d=docs/results/session27
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
o=$OUT
mkdir -p $o/ptx $o/ptxr
R="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DRESTRICT=restrict"
{
PROTO_PTX=$o/ptx timeout 60 $P 115 100 $d/proto_march.cl "5:0:0:8:128 5:0:0:4:128" 2>&1 | grep -E 'registers|order'
PROTO_OPTS="$R" PROTO_PTX=$o/ptxr timeout 60 $P 115 100 $d/proto_march.cl "5:0:0:8:128" 2>&1 | grep -E 'registers|order'
timeout 150 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 5:0:0:5:128 5:0:0:8:128 5:0:0:8:256 5:0:0:23:128 5:0:0:8:64"
echo "== restrict"
PROTO_OPTS="$R" timeout 120 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 5:0:0:5:128 5:0:0:8:128 5:0:0:23:128"
} 2>&1 | tee $o/march2_h200.txt
