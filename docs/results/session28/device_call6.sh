#!/usr/bin/env bash
# Session 28, device call 6 (H200): attempt 37f, the column-order march with one set of connection
# coefficients per piece (MIN=3) against one per centre (MIN=1), as main runs its stages (corrector
# in place and in reverse); TZ 2-4, groups of 64-256.
set -u
d=docs/results/session28
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1"
{
echo "== lean gather"; PROTO_INPLACE=1 PROTO_REVERSE=1 PROTO_OPTS="$B" timeout 60 $P 115 2000 $d/proto_march.cl "0:0:0:0:256" | grep order
echo "== MIN=1"; PROTO_INPLACE=1 PROTO_REVERSE=1 PROTO_OPTS="$B -DMIN=1" timeout 60 $P 115 2000 $d/proto_march.cl "8:0:0:3:128" | grep order
echo "== MIN=3"; PROTO_PTX=/tmp PROTO_INPLACE=1 PROTO_REVERSE=1 PROTO_OPTS="$B -DMIN=3" timeout 150 $P 115 2000 $d/proto_march.cl "8:0:0:3:128 8:0:0:3:64 8:0:0:3:256 8:0:0:2:128 8:0:0:2:256 8:0:0:4:128 8:0:0:4:64" 2>&1 | grep -E '^in place|Used [0-9]+ reg' | grep -v 'Used 14 reg'
for cap in 128 120; do echo "== MIN=3 cap $cap"; PROTO_INPLACE=1 PROTO_REVERSE=1 PROTO_OPTS="$B -DMIN=3 -cl-nv-maxrregcount=$cap" timeout 60 $P 115 2000 $d/proto_march.cl "8:0:0:3:128 8:0:0:4:128" | grep order; done
for N in 64 80 160; do S=2000; [ $N = 160 ] && S=1000; echo "== MIN=3 N=$N"; PROTO_INPLACE=1 PROTO_REVERSE=1 PROTO_OPTS="$B -DMIN=3" timeout 60 $P $N $S $d/proto_march.cl "0:0:0:0:256 8:0:0:3:128 8:0:0:4:128" | grep order; done
} 2>&1 | tee $OUT/piece_coef_h200.txt
