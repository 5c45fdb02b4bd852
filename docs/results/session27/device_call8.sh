#!/usr/bin/env bash
# Session 27, device call 8 (H200): the lean march (attempt 36d) under register caps and at other
# piece lengths; then the full GPU study and throughput series at this commit (scripts/bench_gpu.sh).
set -u
d=docs/results/session27
o=$OUT
P="bash scripts/gpu_run.sh run .device-pkgs/proto_march"
B="-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero -DLEAN=1"
{
PROTO_OPTS="$B" timeout 60 $P 115 2000 $d/proto_march.cl "0:0:0:0:256 5:0:0:2:128 5:0:0:4:128 5:0:0:6:128"
for cap in 80 72 64; do
  echo "== cap $cap"
  PROTO_PTX=/tmp PROTO_OPTS="$B -cl-nv-maxrregcount=$cap" timeout 60 $P 115 2000 $d/proto_march.cl "5:0:0:4:128 5:0:0:4:256" 2>&1 | grep -E 'order|spill' | grep -v ' 0 bytes spill stores'
done
} 2>&1 | tee $o/lean_caps_h200.txt
BENCH_TIMEOUT=430 bash scripts/bench_gpu.sh > $o/bench_gpu.log 2>&1
tail -5 $o/bench_gpu.log
