#!/usr/bin/env bash
# Session 26, device call 6 (H200): is main's in-place corrector (heun_correct writes u, v over the
# step's base) the 7-12% between main's step and the prototype's (which writes the corrected
# state into a second buffer and swaps)? The prototype both ways, interleaved, and main once.
set -u
G="bash scripts/gpu_run.sh run"
P=docs/results/session26/proto_tile.cl
{
for r in 1 2 3; do
  for ip in 0 1; do
    PROTO_INPLACE=$ip timeout 60 $G .device-pkgs/proto_tile 115 2000 $P "0:0:0:0:256" 2>&1 | grep order | sed -E 's/  +/ /g'
  done
done
timeout 100 $G voxbreast bench --device gpu --quick --no-study --sizes 115 --out /tmp/b 2>&1 | grep steps/s
} 2>&1 | tee $OUT/inplace_h200.txt
