#!/usr/bin/env bash
# Session 27, device call 3 (H200): attempt 36c, the branch-free march (ORDER 5) under register caps
# (-cl-nv-maxrregcount: more warps per SM) against the gather, 1.5M cube; tools on the machine.
set -u
d=docs/results/session27
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
o=$OUT
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero"
{
ls -d /usr/local/cuda* 2>/dev/null; which ncu nsys nvcc 2>/dev/null
for cap in 96 80 64; do
  echo "== cap $cap"
  PROTO_PTX=$o PROTO_OPTS="$B -cl-nv-maxrregcount=$cap" timeout 100 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:4:128 5:0:0:4:256 5:0:0:23:128" 2>&1 | grep -E 'registers|order|spill|lmem|stack' | grep -v 'Used 14 reg'
done
} 2>&1 | tee $o/march3_h200.txt
