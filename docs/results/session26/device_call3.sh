#!/usr/bin/env bash
# Session 26, device call 3 (H200): attempt 33 in the prototype (proto_tile.cpp/.cl): main's stage
# pair with each work-group stepping a tile of TX × TY × TZ cells instead of ~2.2 consecutive rows,
# by a list (ORDER 2) or computed (ORDER 3); ORDER 1 (identity list) prices the list's read. The
# 1.5M cube (N 115, partial tiles at its edges) and 128³ (2.1M, whole tiles).
set -u
G="bash scripts/gpu_run.sh run"
P=docs/results/session26/proto_tile.cl
C="0:0:0:0:256 1:0:0:0:256 2:32:2:4:256 2:32:4:2:256 2:32:8:1:256 2:64:2:2:256 2:16:4:4:256 2:8:8:4:256 3:32:2:4:256 3:32:4:2:256 3:32:8:1:256 3:64:2:2:256 3:16:4:4:256 2:32:4:4:512 3:32:4:4:512 2:32:2:2:128 3:32:2:2:128 0:0:0:0:256"
for N in 115 128; do
  timeout 250 $G .device-pkgs/proto_tile $N 2000 $P "$C" 2>&1
done | tee $OUT/tile_h200.txt | grep -E "device|order" | sed -E 's/  +/ /g'
