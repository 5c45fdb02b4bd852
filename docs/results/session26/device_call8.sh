#!/usr/bin/env bash
# Session 26, device call 8 (H200): attempt 35 in the prototype: the second stage stepping the
# elements in reverse order (PROTO_REVERSE=1), so each stage starts on the lines the one before
# wrote last, with the corrector in place (as main) and into a second buffer; 1.5M and 512k,
# three rounds interleaved.
set -u
G="bash scripts/gpu_run.sh run"
P=docs/results/session26/proto_tile.cl
{
for N in 115 80; do for r in 1 2 3; do for rev in 0 1; do for ip in 1 0; do
  echo -n "N $N r$r: "
  PROTO_REVERSE=$rev PROTO_INPLACE=$ip timeout 60 $G .device-pkgs/proto_tile $N 2000 $P "0:0:0:0:256" 2>&1 | grep order | sed -E 's/  +/ /g'
done; done; done; done
} 2>&1 | tee $OUT/reverse_h200.txt
