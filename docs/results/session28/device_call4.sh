#!/usr/bin/env bash
# Session 28, device call 4 (H200): attempt 37d, the column-order march with the MIN connection:
# piece length TZ, work-group size and register caps (1.5M; 512k and 4.1M for the best).
set -u
d=docs/results/session28
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1 -DMIN=1"
{
echo "== lean gather"; PROTO_OPTS="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1" timeout 60 $P 115 2000 $d/proto_march.cl "0:0:0:0:256" | grep order
echo "== MIN=1"; PROTO_PTX=/tmp PROTO_OPTS="$B" timeout 150 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 8:0:0:3:128 8:0:0:3:64 8:0:0:3:256 8:0:0:4:128 8:0:0:4:64 8:0:0:5:64 8:0:0:2:64" 2>&1 | grep -E '^order|Used [0-9]+ reg' | grep -v 'Used 14 reg'
for cap in 128 112 96; do echo "== MIN=1 cap $cap"; PROTO_OPTS="$B -cl-nv-maxrregcount=$cap" timeout 100 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 8:0:0:3:128 8:0:0:3:64 8:0:0:4:128" | grep order; done
for N in 80 160; do echo "== MIN=1 N=$N"; PROTO_OPTS="$B" timeout 60 $P $N 1000 $d/proto_march.cl "0:0:0:0:256 8:0:0:3:128 8:0:0:3:64 8:0:0:4:64" | grep order; done
} 2>&1 | tee $OUT/tz_caps_h200.txt
