#!/usr/bin/env bash
# Session 24, device call 1 (H200): attempt 28, the 1.5M step's state read through the texture
# path (3-D and 2-D images) against buffers (main's gather; a 3-D range), in the standalone
# harness proto_image.cpp (built here, carried in .device-pkgs/); main's quick 1.5M row for scale.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
nvidia-smi --query-gpu=name,driver_version,power.limit,clocks.max.sm --format=csv,noheader > $o/device.txt
P=docs/results/session24/proto_image.cl
{
timeout 150 $G .device-pkgs/proto_image 115 2000 $P
PROTO_SHAPES="32x4x1 8x8x2 8x4x4" timeout 60 $G .device-pkgs/proto_image 80 2000 $P
timeout 60 $G voxbreast bench --quick --no-study --sizes 115 --out /tmp/t 2>&1 | grep -E "^(block)|device|host|copy"
PROTO_SHAPES="32x4x1 8x8x2 8x4x4" timeout 150 $G .device-pkgs/proto_image 115 2000 $P
} 2>&1 | tee $o/image_h200.txt
